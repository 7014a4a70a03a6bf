"""Physics of the stepper cores (spec 10.2, 10.4, 10.5), checked on every core built.

The expectations come from the spec's rules (vectors end on their targets, no rate above
the cap, HALT + GO loses no step, KEEP/RESTORE keeps a partial vector), not from the
implementation's numbers.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from emulator.motion.arith import acc_count, acc_time
from emulator.motion.factory import c_available, create
from emulator.motion.interface import Vector
from gve_fixtures.protocol import SECOND

MAX_RATE = 100_000
AXES = 3

CORES = ["python"] + (["c"] if c_available() else [])
pytestmark = pytest.mark.parametrize("core", CORES)

SETTINGS = settings(max_examples=40, deadline=None, derandomize=True,
                    suppress_health_check=[HealthCheck.too_slow])


def make(stepper: str):
    return create(AXES, MAX_RATE, stepper=stepper)


def vector(steps, *, continuous=True, v=1000, a=20_000, b=MAX_RATE, short=512,
           dwell_ms=5, vk=False, limits=(MAX_RATE,) * AXES) -> Vector:
    return Vector(tuple(steps), continuous, v, a, b, short, dwell_ms * 1_000_000, vk,
                  tuple(limits))


steps_st = st.tuples(*[st.integers(-3000, 3000)] * AXES)
vector_st = st.builds(
    lambda s, c, v, a, b, short: vector(s, continuous=c, v=v, a=a, b=b, short=short),
    steps_st, st.booleans(), st.integers(10, MAX_RATE), st.integers(1, 200).map(lambda x: x * 1000),
    st.integers(10, MAX_RATE), st.integers(1, 5000))


def loaded(core: str, vectors):
    """A core with ``vectors`` pushed 1 ns apart from instant 0."""
    m = make(core)
    for i, v in enumerate(vectors):
        m.push(v, i)
    return m


def run_out(m) -> int:
    end = m.drain_instant()
    if end is None:                       # nothing held (zero-length vectors only)
        end = m.now
    m.advance(end)
    assert not m.flags(end).busy
    return end


def total(vectors) -> tuple[int, ...]:
    return tuple(sum(v.steps[i] for v in vectors) for i in range(AXES))


# -- the arithmetic ---------------------------------------------------------------------

@given(st.integers(0, 10**6), st.integers(0, 10**8), st.integers(0, 2**35))
@settings(max_examples=300, deadline=None, derandomize=True)
def test_acc_time_is_the_first_instant_of_the_step(core, v, a, m):
    if v == 0 and a == 0:
        return
    tau = acc_time(v, a, m)
    assert acc_count(v, a, tau) >= m
    assert tau == 0 or acc_count(v, a, tau - 1) < m


# -- vectors ----------------------------------------------------------------------------

@given(st.lists(vector_st, min_size=1, max_size=6))
@SETTINGS
def test_vectors_end_on_their_targets_and_pulses_add_up(core, vectors):
    m = make(core)
    t = 0
    for v in vectors:
        m.push(v, t)
        t += 1000
    end = run_out(m)
    assert m.position(end) == total(vectors)
    times, masks = m.pulses(0, end + 1)
    assert np.all(np.diff(times) > 0), "pulse instants increase"
    for i in range(AXES):
        fwd = int(((masks >> i) & 1 & ~(masks >> (4 + i)) & 1).sum())
        back = int(((masks >> i) & 1 & (masks >> (4 + i)) & 1).sum())
        assert fwd - back == total(vectors)[i]


@given(st.lists(vector_st, min_size=1, max_size=4), st.data())
@SETTINGS
def test_position_equals_the_pulses_before_it(core, vectors, data):
    m = loaded(core, vectors)
    end = m.drain_instant() or m.now
    times, masks = m.pulses(0, end + 1)
    instant = data.draw(st.integers(0, end))
    before = times <= instant
    expect = []
    for i in range(AXES):
        stepped = ((masks >> i) & 1).astype(bool) & before
        neg = ((masks >> (4 + i)) & 1).astype(bool)
        expect.append(int(stepped.sum() - 2 * (stepped & neg).sum()))
    assert m.position(instant) == tuple(expect)


@given(st.lists(vector_st, min_size=1, max_size=4), st.data())
@SETTINGS
def test_pulse_windows_slice_exactly(core, vectors, data):
    m = loaded(core, vectors)
    end = m.drain_instant() or m.now
    cut = data.draw(st.integers(0, end))
    whole = m.pulses(0, end + 1)
    first, second = m.pulses(0, cut), m.pulses(cut, end + 1)
    assert np.array_equal(whole[0], np.concatenate([first[0], second[0]]))
    assert np.array_equal(whole[1], np.concatenate([first[1], second[1]]))


@given(st.lists(vector_st, min_size=1, max_size=4))
@SETTINGS
def test_no_axis_steps_faster_than_the_variant_allows(core, vectors):
    m = loaded(core, vectors)
    end = run_out(m)
    times, masks = m.pulses(0, end + 1)
    for i in range(AXES):
        axis_times = times[((masks >> i) & 1).astype(bool)]
        if len(axis_times) > 1:
            assert np.diff(axis_times).min() >= SECOND // MAX_RATE


def test_cruise_runs_at_the_commanded_rate(core):
    m = make(core)
    m.push(vector((10_000, 0, 0), continuous=False, v=2000, a=1_000_000), 0)
    times, _ = m.pulses(0, m.drain_instant() + 1)
    middle = np.diff(times[4000:6000])
    assert middle.min() >= SECOND // 2000 and middle.max() <= SECOND // 2000 + 1


def test_path_speed_divides_the_rate_by_the_length(core):
    m = make(core)
    m.push(vector((3000, 4000, 0), continuous=False, v=1000, a=10_000_000, vk=True), 0)
    end = m.drain_instant()
    # |d| = 5000 at 1000/s: 5 s of motion; the dominant Y runs at 800/s
    assert 5 * SECOND <= end - 5_000_000 <= 5 * SECOND + SECOND // 50


def test_axis_limit_caps_the_dominant_rate(core):
    m = make(core)
    m.push(vector((1000, 1000, 0), continuous=False, v=5000, a=10_000_000,
                  limits=(500, MAX_RATE, MAX_RATE)), 0)
    end = m.drain_instant()
    assert end >= 2 * SECOND  # X capped at 500/s over 1000 steps


def test_zero_vector_completes_at_once(core):
    m = make(core)
    m.push(vector((0, 0, 0), continuous=False), 123)
    assert not m.flags(123).busy
    assert m.drain_instant() is None


def test_dwell_before_a_start_from_rest(core):
    m = make(core)
    m.push(vector((10, 0, 0), continuous=False, dwell_ms=20), 0)
    end = run_out(m)
    m.push(vector((10, 0, 0), continuous=False, dwell_ms=20), end)
    times, _ = m.pulses(end + 1, end + 10 * SECOND)
    assert times[0] - end >= 20_000_000


def test_junction_is_faster_than_stopping(core):
    def duration(gap: int) -> int:
        m = make(core)
        m.push(vector((2000, 0, 0), v=1000, b=1000), 0)
        m.push(vector((2000, 0, 0), v=1000, b=1000), gap)
        return m.drain_instant()
    assert duration(1000) < duration(3 * SECOND)


# -- HALT, GO, KEEP, RESTORE, overrides ------------------------------------------------

@given(st.lists(vector_st, min_size=1, max_size=5), st.data())
@SETTINGS
def test_halt_and_resume_end_where_not_halting_ends(core, vectors, data):
    m = loaded(core, vectors)
    end = m.drain_instant() or m.now
    at = data.draw(st.integers(0, end))
    rest = m.halt(at)
    assert rest >= at
    flags = m.flags(rest)
    assert flags.halted and not flags.moving
    still = m.position(rest)
    assert m.position(rest + SECOND) == still, "a halted unit does not move"
    m.resume(rest + SECOND)
    run_out(m)
    assert m.position(m.now) == total(vectors)


@given(st.lists(vector_st, min_size=1, max_size=4), st.data())
@SETTINGS
def test_keep_restore_around_a_detour_loses_no_step(core, vectors, data):
    m = loaded(core, vectors)
    end = m.drain_instant() or m.now
    rest = m.halt(data.draw(st.integers(0, end)))
    saved = m.keep(rest)
    assert m.queued(rest) == 0
    m.push(vector((0, 0, -500), continuous=False), rest)
    m.advance(run_out(m))
    m.push(vector((0, 0, 500), continuous=False), m.now)
    m.advance(run_out(m))
    m.restore(saved, m.now)
    m.set_velocity(data.draw(st.integers(10, MAX_RATE)), m.now)
    m.resume(m.now)
    run_out(m)
    assert m.position(m.now) == total(vectors)


@given(st.lists(vector_st, min_size=1, max_size=4), st.data())
@SETTINGS
def test_overrides_change_speed_not_targets(core, vectors, data):
    m = loaded(core, vectors)
    t = 0
    for _ in range(data.draw(st.integers(1, 4))):
        t += data.draw(st.integers(0, SECOND))
        which = data.draw(st.sampled_from(["xa", "xu", "xd", "xm"]))
        if which == "xa":
            m.set_velocity(data.draw(st.integers(10, MAX_RATE)), t)
        elif which == "xu":
            m.scale_velocity(17, 16, t)
        elif which == "xd":
            m.scale_velocity(15, 16, t, accel=True)
        else:
            m.set_multiplier(data.draw(st.integers(1, 1000)), t)
    run_out(m)
    assert m.position(m.now) == total(vectors)


def test_multiplier_doubles_the_speed(core):
    def duration(percent: int) -> int:
        m = make(core)
        m.set_multiplier(percent, 0)
        m.push(vector((20_000, 0, 0), continuous=False, v=1000, a=10_000_000), 0)
        return m.drain_instant()
    assert abs(duration(100) - 2 * duration(200)) < SECOND // 10


def test_delete_keeps_the_position(core):
    m = make(core)
    m.push(vector((5000, 0, 0)), 0)
    rest = m.halt(SECOND)
    here = m.position(rest)
    m.clear(rest)
    assert m.position(rest) == here and m.queued(rest) == 0
    assert not m.flags(rest).halted


def test_set_position_moves_the_counter_only(core):
    m = make(core)
    m.set_position(1, 100, 0)
    assert m.position(0) == (0, 100, 0)


def test_instant_of_position_finds_the_crossing(core):
    m = make(core)
    m.push(vector((0, 3000, 0), continuous=False), 0)
    t = m.instant_of_position(1, 1234)
    assert t is not None
    assert m.position(t - 1)[1] == 1233 and m.position(t)[1] == 1234
    assert m.instant_of_position(0, 5) is None


# -- the closed form ----------------------------------------------------------------------

def test_a_full_queue_of_huge_vectors_costs_nothing_per_step(core):
    m = create(4, 500_000, stepper=core)
    big = 2**31 - 1
    v = Vector((big, -big, big // 3, 7), True, 500_000, 10_000_000, 500_000, 512, 5_000_000,
               False, (500_000,) * 4)
    for i in range(2048):
        m.push(v, i)
    end = m.drain_instant()
    assert m.position(end) == (2048 * big, -2048 * big, 2048 * (big // 3), 2048 * 7)
    assert m.position(end // 2)[0] > 0


@given(st.integers(100, 20_000), st.integers(10, MAX_RATE), st.integers(1, 200))
@SETTINGS
def test_accelerations_stay_within_a(core, length, rate, kilo):
    """Within one vector the rate between consecutive steps changes by at most A·Δt,
    allowing for instants rounded to whole nanoseconds (docs/motion-model.md)."""
    a = kilo * 1000
    m = make(core)
    m.push(vector((length, 0, 0), continuous=False, v=rate, a=a), 0)
    times, _ = m.pulses(0, m.drain_instant() + 1)
    gaps = np.diff(times).astype(float)[1:-1]          # skip the first and last steps
    if len(gaps) < 2:
        return
    rates = 1e9 / gaps
    change = np.abs(np.diff(rates))
    # a phase boundary may add one more step of A·Δt (up/down are floored)
    allowed = a * (gaps[:-1] + gaps[1:]) / 1e9 + 2e9 / np.minimum(gaps[:-1],
                                                                          gaps[1:]) ** 2 + 1
    assert np.all(change <= allowed), float(np.max(change - allowed))


# -- the spec revision of 2026-11-25 (spec 10.2, 10.4) ----------------------------------

def _first_step_after(m, t: int) -> int:
    times, _ = m.pulses(t + 1, t + 10 * SECOND)
    return int(times[0])


def test_a_c_joins_although_braking_takes_no_whole_step(core):
    """A C whose braking is shorter than a step can still be joined until its last step:
    at A = 1e7 steps/s² V1000 brakes in 0.05 steps."""
    m = make(core)
    m.push(vector((100, 0, 0), v=1000, a=10_000_000), 0)
    m.push(vector((100, 0, 0), v=1000, a=10_000_000), 50 * SECOND // 1000)
    times, _ = m.pulses(0, m.drain_instant() + 1)
    gap = int(np.diff(times).max())
    assert gap <= SECOND // 1000 + 1, "no stop at the junction"


def test_no_dwell_between_continuous_vectors_from_rest(core):
    """'Mezi CONT.vektory tato prodleva není' (M84 12.5.2): a C that comes after a C
    has stopped starts at once; an L waits out T."""
    for continuous, waits in ((True, False), (False, True)):
        m = make(core)
        m.push(vector((10, 0, 0), continuous=continuous, dwell_ms=20), 0)
        end = run_out(m)
        m.push(vector((10, 0, 0), continuous=continuous, dwell_ms=20), end + 1)
        start = _first_step_after(m, end)
        assert (start - end >= 20_000_000) == waits


def test_a_zero_length_c_between_two_c_makes_the_next_start_from_rest(core):
    m = make(core)
    m.push(vector((0, -92, 0), v=1000, a=10_000_000, dwell_ms=24), 0)
    m.push(vector((0, 0, 0), v=1000, a=10_000_000, dwell_ms=24), 1)
    m.push(vector((0, 46, 0), v=1000, a=10_000_000, dwell_ms=24), 2)
    first_end = m.instant_of_position(1, -92)
    start = _first_step_after(m, first_end)
    assert start - first_end >= 24_000_000, "after T from rest"


def test_halt_in_the_final_deceleration_ends_on_the_target(core):
    m = make(core)
    m.push(vector((0, 0, 245), continuous=False, v=1500, a=20_000), 0)
    end = m.drain_instant()
    rest = m.halt(end - 30_000_000)             # 30 ms before the end: braking already
    assert rest == end
    assert m.position(rest) == (0, 0, 245)
    flags = m.flags(rest)
    assert flags.halted and not flags.busy      # nothing is left: RUN = 0
