"""The benchmark's baseline for the C core's pulse trains: a plain exact kernel for one
vector's train (_kernel.c: the steps in order, Bresenham over the axes and an integer
recurrence for the instants), built into the same module. Raises ImportError where the
C core is not available (c_core.py).
"""

from __future__ import annotations

import numpy as np

from emulator.motion.c_core import ffi, lib


def kernel_pulses(steps: tuple[int, ...], t0: int, cruise: int, accel: int
                  ) -> tuple[np.ndarray, np.ndarray]:
    """The pulse train of the vector ``steps`` planned from rest to rest from ``t0`` at
    the cruise rate ``cruise`` and acceleration ``accel``: instants and masks as
    ``Motion.pulses`` gives them (the C core's train for an L vector with no dwell
    whose cruise rate is ``cruise``). ValueError for a vector beyond the kernel's
    range (rates, accelerations and lengths no profile reaches)."""
    axes = len(steps)
    c_steps = ffi.new("int64_t[]", list(steps))
    n = lib.st_kernel_pulses(c_steps, axes, t0, cruise, accel, ffi.NULL, ffi.NULL, 0)
    times = np.empty(n, dtype=np.int64)
    masks = np.empty(n, dtype=np.uint8)
    if lib.st_kernel_pulses(c_steps, axes, t0, cruise, accel,
                            ffi.from_buffer("int64_t[]", times),
                            ffi.from_buffer("uint8_t[]", masks), n) < 0:
        raise ValueError(f"the vector {steps} at {cruise}/s is beyond the kernel's range")
    return times, masks
