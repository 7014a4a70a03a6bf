"""The benchmark's plain kernel (emulator/motion/_kernel.c) computes the C core's own
pulse train for an L vector from rest, and so the Python twin's: the benchmark's ratio
of the two rates compares the same work, and both agree with the definitions."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from emulator.motion.factory import c_available, create
from emulator.motion.interface import Vector

pytestmark = pytest.mark.skipif(not c_available(), reason="the C stepper core is not built "
                                "(the emulator falls back to the Python twin)")

MAX_RATE = 500_000


@given(st.lists(st.one_of(st.integers(-20_000, 20_000), st.sampled_from([0, 1, -1, 2])),
                min_size=1, max_size=4),
       st.one_of(st.integers(1, MAX_RATE), st.integers(1, 50)),
       st.one_of(st.integers(1, 10_000), st.integers(1, 3)), st.integers(0, 10**9))
@example([1], 1, 1, 0)
@example([20_000, -20_000, 1, 0], MAX_RATE, 1, 10**9)
@example([3, -2], 1, 10_000, 0)
@settings(max_examples=120, deadline=None, derandomize=True)
def test_the_kernels_train_is_the_cores_and_the_twins(steps, velocity, accel, t0):
    from emulator.motion.kernel import kernel_pulses
    # an L with no dwell, no short-vector rule and no axis limit below V: the core plans
    # it from rest at t0, cruising at V, as the kernel does
    vector = Vector(tuple(steps), False, velocity, accel * 1000, velocity, 0, 0, False,
                    (MAX_RATE,) * len(steps))
    expected = kernel_pulses(tuple(steps), t0, velocity, accel * 1000)
    for stepper in ("c", "python"):
        m = create(len(steps), MAX_RATE, stepper=stepper)
        m.push(vector, t0)
        end = m.drain_instant()
        times, masks = m.pulses(0, (end or t0) + 1)
        assert np.array_equal(times, expected[0]) and np.array_equal(masks, expected[1])
        assert len(times) == max(abs(d) for d in steps)


def test_a_vector_beyond_the_kernels_range_is_refused_not_computed():
    from emulator.motion.kernel import kernel_pulses
    with pytest.raises(ValueError, match="beyond the kernel's range"):
        kernel_pulses((100,), 0, 2**33, 2**62)   # cruising at 2**33 steps/s
