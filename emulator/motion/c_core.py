"""The C stepper core behind the Motion interface (interface.py).

Raises ImportError when the compiled module ``emulator.motion._stepper_c`` is missing,
or older than its sources and not rebuildable here (rebuild.py): the emulator then uses
the Python twin. Behaves exactly like python_twin.PythonMotion; KEEP returns the same
save structure, so the unit treats both cores alike.
"""

from __future__ import annotations

import numpy as np

from emulator.motion.rebuild import ensure_fresh

ensure_fresh()   # ImportError for a stale build that cannot be rebuilt

from emulator.motion._stepper_c import ffi, lib  # noqa: E402  (ImportError when not built)
from emulator.motion.interface import (  # noqa: E402
    Deviation,
    KeepSave,
    MotionFlags,
    Vector,
)

AXES = 4


class CMotion:
    kind = "c"

    def __init__(self, axes: int, max_rate: int, deviations: Deviation = Deviation.NONE) -> None:
        if not 1 <= axes <= AXES:
            raise ValueError(f"the C core handles 1..{AXES} axes")
        self.axes = axes
        self.max_rate = max_rate
        self.deviations = Deviation(deviations)
        self._m = ffi.gc(lib.st_new(axes, max_rate), lib.st_free)
        if self._m == ffi.NULL:
            raise MemoryError("st_new")
        lib.st_set_deviations(self._m, int(self.deviations))
        self._out = ffi.new("int64_t[4]")
        self._vec = ffi.new("st_vector *")

    # -- conversions ----------------------------------------------------------------
    def _c_vector(self, v: Vector):
        c = self._vec
        steps = list(v.steps) + [0] * (AXES - len(v.steps))
        limits = list(v.axis_limits) + [0] * (AXES - len(v.axis_limits))
        c.steps = steps
        c.axis_limits = limits
        c.continuous = int(v.continuous)
        c.velocity, c.accel, c.brake = v.velocity, v.accel, v.brake
        c.short_, c.dwell, c.path_speed = v.short, v.dwell, int(v.path_speed)
        return c

    def _py_vector(self, c) -> Vector:
        return Vector(tuple(c.steps[i] for i in range(self.axes)), bool(c.continuous),
                      c.velocity, c.accel, c.brake, c.short_, c.dwell, bool(c.path_speed),
                      tuple(c.axis_limits[i] for i in range(self.axes)))

    # -- time -----------------------------------------------------------------------
    def advance(self, t: int) -> None:
        lib.st_advance(self._m, t)

    @property
    def now(self) -> int:
        return lib.st_now(self._m)

    def next_event(self) -> int | None:
        return self._out[0] if lib.st_next_event(self._m, self._out) else None

    def drain_instant(self) -> int | None:
        found = lib.st_drain_instant(self._m, self._out)
        if found < 0:
            raise MemoryError("st_drain_instant")
        return self._out[0] if found else None

    # -- queries ----------------------------------------------------------------------
    def position(self, t: int) -> tuple[int, ...]:
        lib.st_position(self._m, t, self._out)
        return tuple(self._out[i] for i in range(self.axes))

    def physical(self, t: int) -> tuple[int, ...]:
        lib.st_physical(self._m, t, self._out)
        return tuple(self._out[i] for i in range(self.axes))

    def excursion(self, t: int) -> tuple[tuple[int, int], ...]:
        lo, hi = ffi.new("int64_t[4]"), ffi.new("int64_t[4]")
        lib.st_excursion(self._m, t, lo, hi)
        return tuple((lo[i], hi[i]) for i in range(self.axes))

    def flags(self, t: int) -> MotionFlags:
        f = ffi.new("int[4]")
        lib.st_flags(self._m, t, f, f + 1, f + 2, f + 3)
        return MotionFlags(busy=bool(f[0]), moving=bool(f[1]), stopping=bool(f[2]),
                           halted=bool(f[3]))

    def queued(self, t: int) -> int:
        return lib.st_queued(self._m, t)

    def instant_of_position(self, axis: int, value: int) -> int | None:
        found = lib.st_instant_of_position(self._m, axis, value, self._out)
        if found < 0:
            raise MemoryError("st_instant_of_position")
        return self._out[0] if found else None

    def pulses(self, t0: int, t1: int):
        cap = 4096
        while True:
            times = np.empty(cap, dtype=np.int64)
            masks = np.empty(cap, dtype=np.uint8)
            n = lib.st_pulses(self._m, t0, t1, ffi.from_buffer("int64_t[]", times),
                              ffi.from_buffer("uint8_t[]", masks), cap)
            if n < 0:
                raise MemoryError("st_pulses")
            if n <= cap:
                return times[:n].copy(), masks[:n].copy()
            cap = n

    # -- commands -----------------------------------------------------------------------
    def push(self, vector: Vector, t: int) -> None:
        if lib.st_push(self._m, self._c_vector(vector), t):
            raise MemoryError("st_push")

    def halt(self, t: int) -> int:
        return lib.st_halt(self._m, t)

    def resume(self, t: int) -> None:
        lib.st_resume(self._m, t)

    def clear(self, t: int) -> None:
        lib.st_clear(self._m, t)

    def keep(self, t: int) -> KeepSave:
        lib.st_advance(self._m, t)
        done = ffi.new("int64_t *")
        c = ffi.new("st_vector *")
        entries = []
        for i in range(lib.st_entries(self._m)):
            lib.st_entry(self._m, i, c, done)
            entries.append((self._py_vector(c), done[0]))
        saved = KeepSave(tuple(entries), bool(lib.st_halted(self._m)))
        lib.st_clear(self._m, t)
        return saved

    def restore(self, saved: KeepSave, t: int) -> None:
        here = ffi.new("int64_t[4]")
        lib.st_restore_begin(self._m, t, here)
        for vector, done in saved.entries:
            if lib.st_restore_add(self._m, self._c_vector(vector), done):
                raise MemoryError("st_restore_add")
        lib.st_restore_end(self._m, here, int(saved.halted), t)

    def set_position(self, axis: int, value: int, t: int) -> None:
        lib.st_set_position(self._m, axis, value, t)

    def jump(self, axis: int, delta: int, t: int) -> None:
        lib.st_jump(self._m, axis, delta, t)

    def set_velocity(self, velocity: int, t: int, accel: int | None = None) -> None:
        lib.st_set_velocity(self._m, velocity, t, accel is not None, accel or 0)

    def scale_velocity(self, num: int, den: int, t: int, accel: bool = False) -> None:
        lib.st_scale_velocity(self._m, num, den, t, int(accel))

    def set_multiplier(self, percent: int, t: int) -> None:
        lib.st_set_multiplier(self._m, percent, t)
