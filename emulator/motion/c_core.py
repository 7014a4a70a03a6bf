"""The C stepper core behind the Motion interface (interface.py).

Raises ImportError when the compiled module ``emulator.motion._stepper_c`` is missing,
or older than its sources and not rebuildable here (rebuild.py): the emulator then uses
the Python twin. Behaves exactly like python_twin.PythonMotion; KEEP returns the same
save structure, so the unit treats both cores alike.

Crossing into C costs more than most of what the core does there, so no call makes
cdata of its own: a vector is packed (struct) into a buffer the object keeps, answers
come back through an array it keeps, and the flags are one int indexing the 16
possible MotionFlags. Pushes wait in a batch and go into C in one call, before any
other call reaches the core: every other method sees the queue exactly as after those
pushes one by one (a vector that does not pack is refused by its own push).
"""

from __future__ import annotations

import struct
from typing import Any

from emulator.motion.build_stepper import AXES
from emulator.motion.rebuild import ensure_fresh

ensure_fresh()   # ImportError for a stale build that cannot be rebuilt

from emulator.motion._stepper_c import ffi, lib  # noqa: E402  (ImportError when not built)
from emulator.motion.interface import (  # noqa: E402
    Deviation,
    KeepSave,
    MotionFlags,
    Vector,
)

#: st_vector as the C compiler lays it out (native alignment): steps[AXES], continuous,
#: velocity, accel, brake, short_, dwell, path_speed, axis_limits[AXES]
VECTOR = struct.Struct(f"@{AXES}qi5qi{AXES}q")
#: st_timed_vector: the instant of a push, then its st_vector
TIMED = struct.Struct(f"@q{AXES}qi5qi{AXES}q")
#: pushes held before they go into C together (any other call sends them at once)
BATCH = 256
_pack, _pack_timed = VECTOR.pack_into, TIMED.pack_into


def _check_layout() -> None:
    """Every field packed lands in the C field of its name."""
    values = tuple(range(1, 17))
    buf = bytearray(TIMED.size)
    _pack_timed(buf, 0, *values)
    c = ffi.from_buffer("st_timed_vector *", buf)
    v = c.v
    got = (c.t, *v.steps, v.continuous, v.velocity, v.accel, v.brake, v.short_, v.dwell,
           v.path_speed, *v.axis_limits)
    if (VECTOR.size, TIMED.size) != (ffi.sizeof("st_vector"), ffi.sizeof("st_timed_vector")) \
            or ffi.offsetof("st_timed_vector", "v") != TIMED.size - VECTOR.size \
            or got != values:
        raise ImportError("the C core's vector layout is not the one c_core.py packs")


_check_layout()
#: every flags word st_flags can give, as the MotionFlags it stands for
_FLAGS = tuple(MotionFlags(busy=bool(bits & lib.ST_BUSY), moving=bool(bits & lib.ST_MOVING),
                           stopping=bool(bits & lib.ST_STOPPING),
                           halted=bool(bits & lib.ST_HALTED)) for bits in range(16))
#: per axis count, the (lowest, highest) pairs of st_excursion's answer (lows, then highs)
_PAIRS = {
    1: lambda b: ((b[0], b[4]),),
    2: lambda b: ((b[0], b[4]), (b[1], b[5])),
    3: lambda b: ((b[0], b[4]), (b[1], b[5]), (b[2], b[6])),
    4: lambda b: ((b[0], b[4]), (b[1], b[5]), (b[2], b[6]), (b[3], b[7])),
}
_unpack = ffi.unpack
_st_push_many, _st_position, _st_physical = lib.st_push_many, lib.st_position, lib.st_physical
_st_excursion, _st_flags, _st_queued = lib.st_excursion, lib.st_flags, lib.st_queued


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
        self._out = ffi.new(f"int64_t[{2 * AXES}]")
        self._buf = bytearray(VECTOR.size)
        self._vec = ffi.from_buffer("st_vector *", self._buf)
        self._pad = (0,) * (AXES - axes)
        self._pairs = _PAIRS[axes]
        self._batch = bytearray(TIMED.size * BATCH)
        self._batch_c = ffi.from_buffer("st_timed_vector[]", self._batch)
        self._held = 0                         # pushes in the batch

    def _send(self) -> None:
        """The held pushes into the core, in order."""
        held, self._held = self._held, 0
        if _st_push_many(self._m, self._batch_c, held) != held:
            raise MemoryError("st_push")

    # -- conversions ----------------------------------------------------------------
    def _c_vector(self, v: Vector):
        """The vector packed into the object's one st_vector (valid until the next)."""
        # named values, not starred ones: the call then builds no argument tuple
        s0, s1, s2, s3 = v.steps + self._pad
        l0, l1, l2, l3 = v.axis_limits + self._pad
        try:
            _pack(self._buf, 0, s0, s1, s2, s3, v.continuous, v.velocity, v.accel, v.brake,
                  v.short, v.dwell, v.path_speed, l0, l1, l2, l3)
        except struct.error as err:
            raise OverflowError(f"a vector beyond the C core's 64-bit range: {err}") from err
        return self._vec

    def _py_vector(self, c) -> Vector:
        return Vector(tuple(c.steps[i] for i in range(self.axes)), bool(c.continuous),
                      c.velocity, c.accel, c.brake, c.short_, c.dwell, bool(c.path_speed),
                      tuple(c.axis_limits[i] for i in range(self.axes)))

    # -- time -----------------------------------------------------------------------
    def advance(self, t: int) -> None:
        if self._held:
            self._send()
        lib.st_advance(self._m, t)

    @property
    def now(self) -> int:
        if self._held:
            self._send()
        return lib.st_now(self._m)

    def next_event(self) -> int | None:
        if self._held:
            self._send()
        return self._out[0] if lib.st_next_event(self._m, self._out) else None

    def drain_instant(self) -> int | None:
        if self._held:
            self._send()
        found = lib.st_drain_instant(self._m, self._out)
        if found < 0:
            raise MemoryError("st_drain_instant")
        return self._out[0] if found else None

    # -- queries ----------------------------------------------------------------------
    def _core(self) -> Any:
        """The core with every held push sent: what a query must see."""
        if self._held:
            self._send()
        return self._m

    def position(self, t: int) -> tuple[int, ...]:
        _st_position(self._core(), t, self._out)
        return tuple(_unpack(self._out, self.axes))

    def physical(self, t: int) -> tuple[int, ...]:
        _st_physical(self._core(), t, self._out)
        return tuple(_unpack(self._out, self.axes))

    def excursion(self, t: int) -> tuple[tuple[int, int], ...]:
        _st_excursion(self._core(), t, self._out)
        return self._pairs(_unpack(self._out, 2 * AXES))

    def flags(self, t: int) -> MotionFlags:
        return _FLAGS[_st_flags(self._core(), t)]

    def queued(self, t: int) -> int:
        return _st_queued(self._core(), t)

    def instant_of_position(self, axis: int, value: int) -> int | None:
        if self._held:
            self._send()
        found = lib.st_instant_of_position(self._m, axis, value, self._out)
        if found < 0:
            raise MemoryError("st_instant_of_position")
        return self._out[0] if found else None

    def pulses(self, t0: int, t1: int):
        if self._held:
            self._send()
        # the train's length first, then the train into arrays of that length
        n = lib.st_pulses(self._m, t0, t1, ffi.NULL, ffi.NULL, 0)
        if n < 0:
            raise MemoryError("st_pulses")
        # only pulse trains need numpy: a unit (a co-simulator's) starts without it
        import numpy as np

        times = np.empty(n, dtype=np.int64)
        masks = np.empty(n, dtype=np.uint8)
        if n and lib.st_pulses(self._m, t0, t1, ffi.from_buffer("int64_t[]", times),
                               ffi.from_buffer("uint8_t[]", masks), n) != n:
            raise MemoryError("st_pulses")
        return times, masks

    # -- commands -----------------------------------------------------------------------
    def push(self, vector: Vector, t: int) -> None:
        held, pad = self._held, self._pad
        # named values, not starred ones: the call then builds no argument tuple
        s0, s1, s2, s3 = vector.steps + pad
        l0, l1, l2, l3 = vector.axis_limits + pad
        try:
            _pack_timed(self._batch, held * TIMED.size, t, s0, s1, s2, s3, vector.continuous,
                        vector.velocity, vector.accel, vector.brake, vector.short,
                        vector.dwell, vector.path_speed, l0, l1, l2, l3)
        except struct.error as err:
            raise OverflowError(f"a vector beyond the C core's 64-bit range: {err}") from err
        self._held = held + 1
        if held + 1 == BATCH:
            self._send()

    def halt(self, t: int) -> int:
        if self._held:
            self._send()
        return lib.st_halt(self._m, t)

    def resume(self, t: int) -> None:
        if self._held:
            self._send()
        lib.st_resume(self._m, t)

    def clear(self, t: int) -> None:
        if self._held:
            self._send()
        lib.st_clear(self._m, t)

    def keep(self, t: int) -> KeepSave:
        if self._held:
            self._send()
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
        if self._held:
            self._send()
        here = ffi.new(f"int64_t[{AXES}]")
        lib.st_restore_begin(self._m, t, here)
        for vector, done in saved.entries:
            if lib.st_restore_add(self._m, self._c_vector(vector), done):
                raise MemoryError("st_restore_add")
        lib.st_restore_end(self._m, here, int(saved.halted), t)

    def set_position(self, axis: int, value: int, t: int) -> None:
        if self._held:
            self._send()
        lib.st_set_position(self._m, axis, value, t)

    def jump(self, axis: int, delta: int, t: int) -> None:
        if self._held:
            self._send()
        lib.st_jump(self._m, axis, delta, t)

    def set_velocity(self, velocity: int, t: int, accel: int | None = None) -> None:
        if self._held:
            self._send()
        lib.st_set_velocity(self._m, velocity, t, accel is not None, accel or 0)

    def scale_velocity(self, num: int, den: int, t: int, accel: bool = False) -> None:
        if self._held:
            self._send()
        lib.st_scale_velocity(self._m, num, den, t, int(accel))

    def set_multiplier(self, percent: int, t: int) -> None:
        if self._held:
            self._send()
        lib.st_set_multiplier(self._m, percent, t)
