"""The motion interface: what the unit asks of its stepper core (spec 10.2, 10.4, 10.5).

The unit speaks the protocol; the stepper core owns the CONT buffer and where every
axis is at every instant. Two implementations stand behind this interface and must give
identical results: the pure-Python twin (the readable reference) and the C core through
cffi. Time is an ``int`` of nanoseconds on the emulator's clock; positions are ``int``
counter units (1/16 steps on the GVE54: the unit scales vectors before pushing them).

Nothing here iterates over steps: every query is closed form, so a queue of 2048
vectors of 2**31 steps costs nothing per step to advance through.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntFlag
from typing import Protocol, runtime_checkable


@dataclass(frozen=True)
class Vector:
    """A vector as accepted, with the modal parameters it captured (spec 10.1).

    ``steps`` are relative counter units per axis (the length is the core's axis count).
    Rates are pulses per second of the counter unit, ``accel`` pulses per second².
    """

    steps: tuple[int, ...]
    continuous: bool        # C (True) or L (False)
    velocity: int           # V
    accel: int              # A × 1000
    brake: int              # B: exit rate at a junction with a following C
    short: int              # $: n < short → a short vector, cruising only towards B
    dwell: int              # T in nanoseconds
    path_speed: bool        # VK (True: speed along |d| without the A axis) or VN
    axis_limits: tuple[int, ...]   # VL per axis (the variant max where VL is absent)


@dataclass(frozen=True)
class MotionFlags:
    """The state the status word ST6 and the error rules need (spec 5, 10.3).

    - ``busy``: a vector is being processed or pending (RUN), including an interrupted
      remainder waiting for GO.
    - ``moving``: executing, braking or dwelling (the "moving" of spec 5).
    - ``stopping``: a stop ramp requested by halt() is in progress (STOP).
    - ``halted``: stopped by halt() and not resumed (the motion side of INTA).
    """

    busy: bool
    moving: bool
    stopping: bool
    halted: bool


@dataclass(frozen=True)
class KeepSave:
    """What KEEP takes from the queue (spec 10.5): every held vector with the dominant
    steps it has done (the interrupted one first), and whether the queue was halted."""

    entries: tuple[tuple[Vector, int], ...] = ()
    halted: bool = False


#: RESTORE with nothing saved restores this: an empty queue (spec 10.5 [D])
EMPTY_SAVE = KeepSave()


class Deviation(IntFlag):
    """Deliberate deviations from the motion model a core can be built with: the
    mutants of ``emulator/mutants.py`` (and the readings of ``emulator/readings.py``)
    whose behaviour lives in the stepper core. Both
    cores implement every flag alike; a clean core has none."""

    NONE = 0
    ZERO_LENGTH_JUNCTION = 1   # a zero-length C passes a junction rate on to the next C
    CONTINUOUS_DWELL = 2       # a C whose braking takes no whole step cannot be joined
                               # after it is planned, and T also separates C vectors
    HALT_SHORT = 4             # H in the final deceleration lays a ramp of its own
    JUNCTION_STOPS = 8         # B ignored: every C brakes to rest at its end
    HALT_DEAD = 16             # H stops at once, without a ramp
    GO_AT_SPEED = 32           # G resumes at the cruise rate instead of from rest
    NEXT_BRAKE = 64            # a junction is passed at the next C's B (a reading)
    JUNCTION_UNBRAKED = 128    # B caps no junction: a C exits at the rate the next allows
    REVERSAL_STOPS = 256       # a C brakes to rest where an axis reverses (a reading)


@runtime_checkable
class Motion(Protocol):
    """A stepper core for one unit. Created by :func:`emulator.motion.factory.create`.

    All mutating calls take the instant ``t`` at which they happen; ``t`` never goes
    backwards. Every call first advances the model to ``t``.
    """

    axes: int
    max_rate: int

    # -- time ---------------------------------------------------------------------
    def advance(self, t: int) -> None:
        """Move the model's present to ``t`` (retire finished vectors, finish ramps)."""

    @property
    def now(self) -> int:
        """The model's present."""

    def next_event(self) -> int | None:
        """The next instant after ``now`` at which :meth:`flags` or :meth:`queued`
        changes without any call (a vector retires, a ramp or dwell ends), or None."""

    def drain_instant(self) -> int | None:
        """When the queue empties with no further calls, or None (halted, or empty)."""

    # -- queries ------------------------------------------------------------------
    def position(self, t: int) -> tuple[int, ...]:
        """Counter value of every axis at ``t`` (advances to ``t`` first)."""

    def physical(self, t: int) -> tuple[int, ...]:
        """Where every axis physically is at ``t``, in counter units: the counter plus
        what :meth:`set_position` took away; only motion and :meth:`jump` move it."""

    def excursion(self, t: int) -> tuple[tuple[int, int], ...]:
        """Per axis the lowest and highest physical position since the core was
        created (up to ``t``)."""

    def flags(self, t: int) -> MotionFlags:
        """The state flags at ``t``."""

    def queued(self, t: int) -> int:
        """Vectors held at ``t``, the executing one and an interrupted remainder
        included: what counts against the CONT buffer (spec 10.1)."""

    def instant_of_position(self, axis: int, value: int) -> int | None:
        """The first instant ≥ ``now`` at which ``axis``'s counter equals ``value``
        under the current plan, or None if it never does (for W and virtual switches)."""

    def pulses(self, t0: int, t1: int):  # -> tuple[numpy.ndarray, numpy.ndarray]
        """The pulse train in [t0, t1): step instants (int64 ns, increasing) and a
        mask per instant (uint8: bit i = axis i stepped, bit 4+i = axis i negative).
        Only for the past and present (t1 ≤ now + planned future is allowed: the plan
        is deterministic until the next call that changes it)."""

    # -- commands -----------------------------------------------------------------
    def push(self, vector: Vector, t: int) -> None:
        """Accept a vector at ``t`` (the unit has checked room and the L rule).
        While halted it waits in the queue until :meth:`resume`."""

    def halt(self, t: int) -> int:
        """Begin a stop on the ramp at ``t`` (it may run into following vectors; a
        vector already braking to rest at its end keeps that ramp and ends on its
        target). Returns the instant the motion is at rest. Idempotent while stopping."""

    def resume(self, t: int) -> None:
        """GO: continue the interrupted vector from the exact step it stopped at,
        accelerating from rest, then the rest of the queue."""

    def clear(self, t: int) -> None:
        """DELETE: drop every held vector (position unchanged). Only while at rest."""

    def keep(self, t: int) -> KeepSave:
        """KEEP: save the held vectors (an interrupted vector with the step it reached)
        and leave the queue empty. Only while at rest."""

    def restore(self, saved: KeepSave, t: int) -> None:
        """RESTORE: put a save back (replacing what is held); the axes do not move."""

    def set_position(self, axis: int, value: int, t: int) -> None:
        """N / N<axis>: set a counter (the axis does not move). Only while nothing is
        held."""

    def jump(self, axis: int, delta: int, t: int) -> None:
        """The axis moved by ``delta`` outside the planner (the W reference run, which
        the unit times itself): counter and physical position move, the excursion
        covers the way. Only while nothing is held."""

    def set_velocity(self, velocity: int, t: int, accel: int | None = None) -> None:
        """XA: every held vector (the running one from ``t``) takes ``velocity``
        (and ``accel`` when given: the GVE54 also exchanges acceleration)."""

    def scale_velocity(self, num: int, den: int, t: int, accel: bool = False) -> None:
        """XU (17/16) / XD (15/16): scale every held vector's velocity (and
        acceleration when ``accel``) by num/den from ``t``."""

    def set_multiplier(self, percent: int, t: int) -> None:
        """XM: an override applying at once to the running and every held vector and
        to later ones, until the next XM (speed = V·percent/100, axis rates ≤ VL)."""
