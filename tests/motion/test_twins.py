"""The C core and the Python twin are bit-identical: the same random sequences of
pushes, waits, halts, resumes, overrides, KEEP/RESTORE, DELETE and N give the same
positions, flags, queue lengths, events, drain instants and pulse trains."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from emulator.motion.arith import acc_count, acc_time
from emulator.motion.factory import c_available, create
from emulator.motion.interface import Deviation, Vector

pytestmark = pytest.mark.skipif(not c_available(), reason="the C stepper core is not built "
                                "(the emulator falls back to the Python twin)")

SETTINGS = settings(max_examples=60, deadline=None, derandomize=True,
                    suppress_health_check=list(HealthCheck))


@given(st.integers(0, 8_000_000), st.integers(0, 160_000_000), st.integers(0, 2**35),
       st.integers(0, 2**40))
@settings(max_examples=500, deadline=None, derandomize=True)
def test_primitives_are_identical(v, a, m, tau):
    from emulator.motion._stepper_c import lib
    if v == 0 and a == 0:
        return
    assert lib.st_acc_time(v, a, m) == acc_time(v, a, m)
    if acc_count(v, a, tau) < 2**62:
        assert lib.st_acc_count(v, a, tau) == acc_count(v, a, tau)


def vectors(axes: int, max_rate: int):
    return st.builds(
        lambda steps, c, v, a, b, short, t, vk, vl: Vector(
            tuple(steps), c, v, a * 1000, b, short, t * 1_000_000, vk, tuple(vl)),
        st.lists(st.one_of(st.integers(-3000, 3000), st.integers(-2**31 + 1, 2**31 - 1)),
                 min_size=axes, max_size=axes),
        st.booleans(), st.integers(10, max_rate), st.integers(1, 10000),
        st.integers(10, max_rate), st.integers(1, 5000), st.integers(1, 24), st.booleans(),
        st.lists(st.integers(10, max_rate), min_size=axes, max_size=axes))


def ops(axes: int, max_rate: int):
    return st.lists(st.one_of(
        st.tuples(st.just("push"), vectors(axes, max_rate)),
        st.tuples(st.just("wait"), st.integers(0, 3_000_000_000)),
        st.tuples(st.just("halt"), st.none()),
        st.tuples(st.just("resume"), st.none()),
        st.tuples(st.just("xa"), st.integers(10, max_rate)),
        st.tuples(st.just("xu"), st.none()),
        st.tuples(st.just("xd"), st.none()),
        st.tuples(st.just("xm"), st.integers(1, 1000)),
        st.tuples(st.just("keep"), st.none()),
        st.tuples(st.just("restore"), st.none()),
        st.tuples(st.just("clear"), st.none()),
        st.tuples(st.just("set"), st.tuples(st.integers(0, axes - 1), st.integers(-1000, 1000))),
        st.tuples(st.just("jump"), st.tuples(st.integers(0, axes - 1), st.integers(-1000, 1000))),
    ), max_size=25)


def observe(m, t: int):
    return (m.position(t), m.physical(t), m.excursion(t), m.flags(t), m.queued(t),
            m.next_event(), m.drain_instant())


@pytest.mark.parametrize(("axes", "max_rate"),
                         [(1, 20_000), (2, 250_000), (3, 100_000), (4, 500_000)])
@given(data=st.data())
@SETTINGS
def test_twins_agree_step_by_step(axes, max_rate, data):
    # the deliberate deviations (mutants) too: both cores plant them alike
    flags = [0, 0, 0, *(1 << i for i in range(len(Deviation)))]
    deviations = Deviation(data.draw(st.sampled_from(flags)))
    py = create(axes, max_rate, stepper="python", deviations=deviations)
    c = create(axes, max_rate, stepper="c", deviations=deviations)
    t = 0
    saves = {}
    for op, arg in data.draw(ops(axes, max_rate)):
        t += data.draw(st.integers(0, 50_000_000))
        for name, m in (("py", py), ("c", c)):
            if op == "push":
                m.push(arg, t)
            elif op == "wait":
                m.advance(t + arg)
            elif op == "halt":
                m.halt(t)
            elif op == "resume":
                m.resume(t)
            elif op == "xa":
                m.set_velocity(arg, t)
            elif op == "xu":
                m.scale_velocity(17, 16, t)
            elif op == "xd":
                m.scale_velocity(15, 16, t, accel=True)
            elif op == "xm":
                m.set_multiplier(arg, t)
            elif op == "keep":
                saves[name] = m.keep(max(t, m.now))
            elif op == "restore" and name in saves:
                m.restore(saves[name], max(t, m.now))
            elif op == "clear":
                m.clear(t)
            elif op == "set":
                m.set_position(*arg, t)
            elif op == "jump":
                m.jump(*arg, t)
        if op == "keep":
            assert saves["py"] == saves["c"]
        t = max(t, py.now)
        assert observe(py, t) == observe(c, t)
        later = t + data.draw(st.integers(0, 5_000_000_000))
        assert py.position(later) == c.position(later)
        assert py.flags(later) == c.flags(later)
        assert py.instant_of_position(0, 5) == c.instant_of_position(0, 5)
    end = (py.drain_instant() or t) + 1
    window = min(end, t + 2_000_000_000)
    p_times, p_masks = py.pulses(0, window)
    c_times, c_masks = c.pulses(0, window)
    assert np.array_equal(p_times, c_times) and np.array_equal(p_masks, c_masks)
    cut = data.draw(st.integers(0, window))
    first, second = c.pulses(0, cut), c.pulses(cut, window)
    assert np.array_equal(np.concatenate([first[0], second[0]]), c_times)
    assert np.array_equal(np.concatenate([first[1], second[1]]), c_masks)


@given(st.lists(st.integers(-5000, 5000), min_size=2, max_size=2),
       st.integers(2**31, 2**33), st.integers(2**40, 2**44))
@settings(max_examples=20, deadline=None, derandomize=True)
def test_trains_beyond_the_walks_range_are_the_twins_too(steps, velocity, accel):
    # accelerations and rates no profile reaches (from 2**40 steps/s², or past 2**61 / 2e9
    # steps/s, the C core's trains take each instant by its definition, not one from the
    # other): still the twin's, bit for bit
    vector = Vector(tuple(steps), False, velocity, accel, velocity, 0, 0, False,
                    (2**34,) * 2)
    trains = []
    for stepper in ("python", "c"):
        m = create(2, 2**34, stepper=stepper)
        m.push(vector, 0)
        trains.append(m.pulses(0, (m.drain_instant() or 0) + 1))
    assert all(np.array_equal(p, c) for p, c in zip(*trains, strict=True))
    assert len(trains[0][0]) == max(abs(d) for d in steps)
