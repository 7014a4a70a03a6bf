"""The suite's motion model against figures worked out by hand from spec 10.2, 10.4 and
the definitions of docs/motion-model.md (never from the emulator)."""

from __future__ import annotations

import math

import pytest

from conformance.motion.arith import acc_count, acc_time, axis_steps
from conformance.motion.model import MotionModel
from conformance.motion.plan import Params, cruise_rate, junction_rate, plan
from gve_fixtures.protocol import SECOND

MS = 1_000_000


def params(**kw) -> Params:
    base = {"V": 1000, "A": 20_000, "B": 100_000, "dollar": 512, "T": 5 * MS,
            "max_rate": 100_000}
    return Params(**{**base, **kw})


@pytest.mark.parametrize(("v", "a", "m", "tau"), [
    (1000, 0, 1, SECOND // 1000),          # cruising at 1000/s: a step per ms
    (1000, 0, 3, 3 * SECOND // 1000),
    (3, 0, 1, 333_333_334),                # the least whole ns: ceil(1e9 / 3)
    (0, 20_000, 1, 10 * MS),               # from rest at 20 000/s²: ½·a·τ² = 1 at τ = 10 ms
    (0, 20_000, 4, 20 * MS),
])
def test_step_instants(v, a, m, tau):
    assert acc_time(v, a, m) == tau
    assert acc_count(v, a, tau) == m and acc_count(v, a, tau - 1) == m - 1


def test_count_and_time_are_inverse():
    for v, a in ((0, 7_000), (1234, 0), (500, 3_000_000)):
        for m in range(1, 200, 7):
            t = acc_time(v, a, m)
            assert acc_count(v, a, t) >= m > acc_count(v, a, t - 1)


@pytest.mark.parametrize(("d", "n", "k", "steps"), [
    (3, 4, 2, 2),          # 1.5 rounds half up
    (-3, 4, 2, -2),
    (1, 3, 1, 0),          # 0.33
    (2, 3, 1, 1),          # 0.67
    (7, 7, 7, 7),          # every vector ends on its target
])
def test_axis_steps_round_half_up(d, n, k, steps):
    assert axis_steps(d, n, k) == steps


def test_cruise_rates():
    assert cruise_rate((600, -200, 0), params(V=3000), 100) == 3000           # VN
    assert cruise_rate((300, 400, 0), params(V=2000, VK=True), 100) == 1600   # V·n/|d|
    assert cruise_rate((300, 400, 0, 100), params(V=2000, VK=True), 100) == 1600  # A not in |d|
    assert cruise_rate((400, 400, 0), params(V=2000, VL=(500, 10**5, 10**5)), 100) == 500
    assert cruise_rate((400, 100, 0), params(V=2000, VL=(10**5, 300, 10**5)), 100) == 1200
    assert cruise_rate((100, 0, 0), params(V=2000, B=300, dollar=1000), 100) == 300  # short
    assert cruise_rate((1000, 0, 0), params(V=2000, B=300, dollar=1000), 100) == 2000
    assert cruise_rate((1000, 0, 0), params(V=1000), 250) == 2500           # XM250
    assert cruise_rate((1000, 0, 0), params(V=90_000), 200) == 100_000      # the max rate


def test_junction_rate_lets_the_next_vector_stop():
    p = params(B=5000)
    # the next C of 20 steps at 1000 steps/s² stops from √(2·1000·20) = 200 steps/s
    assert junction_rate(3000, p, 3000, 1000, 20) == 200
    assert junction_rate(3000, params(B=500), 3000, 1000, 10_000) == 500


def test_a_trapezoid_accelerates_cruises_and_brakes():
    # from rest to 1000/s at 20 000/s²: 1000²/(2·20 000) = 25 steps up and down
    segs = plan(0, 100, 0, 1000, 0, 20_000)
    assert [s.length for s in segs] == [25, 50, 25]
    assert [s.rev for s in segs] == [False, False, True]
    up = math.isqrt(2 * 25 * SECOND**2 // 20_000)      # ½·a·τ² = 25
    assert abs(segs[0].end - up) <= 1
    assert segs[1].end - segs[0].end == 50 * MS         # 50 steps at 1000/s
    assert sum(s.count(10**12) for s in segs) == 100


def test_a_short_trapezoid_peaks_where_the_curves_meet():
    segs = plan(0, 10, 0, 1000, 0, 20_000)
    assert sum(s.length for s in segs) == 10 and segs[-1].rev


def _model(*pushes, origin=(0, 0, 0)):
    m = MotionModel(list(origin))
    for t, d, kind, p in pushes:
        m.push(t, d, kind, p)
    return m


def test_a_line_from_rest_runs_at_v_and_ends_on_target():
    p = params(A=10_000_000, V=1000)             # up = 1000²/2e7 = 0: at V at once
    m = _model((0, (300, -100, 0), "L", p))
    m.advance(SECOND)
    assert m.position(150 * MS) == [150, -50, 0]
    assert m.position(SECOND) == [300, -100, 0]


def test_a_unit_that_dwells_before_every_start_from_rest_starts_later_not_at_junctions():
    p = params(A=10_000_000, V=1000, T=20 * MS)
    m = MotionModel([0, 0, 0], start_delay=2 * MS)
    m.push(0, (100, 0, 0), "C", p)                # long at rest: starts at 2 ms, not 0
    m.push(1 * MS, (100, 0, 0), "C", p)           # continuous: no delay at the junction
    m.advance(SECOND)
    assert m.position(12 * MS)[0] == 10 and m.position(152 * MS)[0] == 150
    m.push(300 * MS, (100, 0, 0), "L", p)         # from rest: T after the rest at 202 ms
    m.advance(SECOND)
    assert m.position(322 * MS)[0] == 220         # started at max(302, 222) ms


def test_t_separates_vectors_from_rest_but_not_continuous_ones():
    p = params(A=10_000_000, V=1000, T=20 * MS)
    m = _model((0, (100, 0, 0), "L", p))
    m.advance(100 * MS)                           # the first L ends at 100 ms
    m.push(101 * MS, (100, 0, 0), "L", p)         # waits until 120 ms
    m.advance(SECOND)
    assert m.position(119 * MS)[0] == 100 and m.position(130 * MS)[0] == 110
    c = _model((0, (100, 0, 0), "C", p), (1 * MS, (100, 0, 0), "C", p))
    c.advance(SECOND)
    assert c.position(150 * MS)[0] == 150          # straight on at the junction


def test_a_zero_length_c_breaks_the_junction():
    p = params(A=10_000_000, V=1000, T=20 * MS)
    m = _model((0, (100, 0, 0), "C", p), (1, (0, 0, 0), "C", p), (2, (100, 0, 0), "C", p))
    m.advance(SECOND)
    assert m.position(110 * MS)[0] == 100          # the third dwells T after the first
    assert m.position(130 * MS)[0] == 110


def test_halt_brakes_over_v_squared_over_2a_and_go_starts_from_rest():
    p = params(A=2_000, V=1000)                    # 250 steps to reach V
    m = _model((0, (5000, 0, 0), "C", p))
    t = 2 * SECOND                                 # cruising at 1000/s
    k = m.position(t)[0]
    rest = m.halt(t)
    m.advance(rest + SECOND)
    assert m.position(rest)[0] == k + 1000**2 // (2 * 2_000)    # 250 steps of ramp
    assert rest - t == pytest.approx(SECOND // 2, abs=2 * MS)    # v/a = 0.5 s
    m.go(rest + SECOND)
    m.advance(rest + 2 * SECOND)
    # from rest at 2000/s²: ½·a·τ² steps after 100 ms (plus the T dwell of 5 ms already over)
    assert m.position(rest + SECOND + 100 * MS)[0] == k + 250 + 10
