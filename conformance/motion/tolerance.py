"""When a frame was processed, and how far a position read from a moving unit may be
from the model's.

A unit answers ``P``/``PF`` with the step counts at the instant it processes the frame
(spec 10.2). The host cannot see that instant; it knows when it began sending the frame
(``sent_at``) and when the answer had arrived (``received_at``). Between them lie the
frame's bytes on the wire, the unit's processing and the answer's bytes:

    sent_at ── frame bytes ──▶ [processed] ── answer bytes ──▶ received_at

- On the embedded emulator (virtual time) every byte takes exactly ``round(1e10/baud)`` ns
  and nothing else takes time, so the instant is known exactly:
  ``sent_at + len(frame)·byte = received_at − len(answer)·byte``. The window has width 0.
- On a paced line (a serial port: the UART sends at the baud rate) the frame's and the
  answer's bytes take at least their transmission time, so the window is
  ``[sent_at + len(frame)·byte, received_at − len(answer)·byte]``; what is left is the
  observed latency (driver, USB, the unit's processing).
- On an unpaced line (a pty or TCP, where bytes may take no time) only
  ``[sent_at, received_at]`` is sure.

On a real line the unit may act on a frame a little outside even that window (an
adapter's latency timer delays the answer, not only the frame; a unit's own loop acts a
tick after it answered): every window is widened on both sides by the line's band
(:mod:`conformance.link.line_band`, from the round trip measured at the session's start
and the case's own), zero in virtual time.

A position judged against the model is accepted within the model's positions over the
whole window (the model is evaluated at both ends and at every vector boundary inside),
widened by ``steps``: none where exactness is ours (the reference emulator, or a target
run with --strict, in virtual time), else one step of placement on each axis — the
model's step placement and rounding are the project's reading (docs/motion-model.md), not
the manuals', so a simulator of somebody else's is judged as a real unit is even in
virtual time; and so is the instant an ``H`` answers (:func:`step_period`):
:class:`Tolerance` carries the figures, which every motion check prints (the line's band
and the steps either side it allowed, e.g. ``±1.8 ms line, ±7 steps``).

The differential fuzzer compares two targets' readings the same way:
:func:`reading_band` is how many steps two readings taken in two windows may differ by
while the axes run at up to ``rate`` steps per second.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from conformance.link.line_band import EXACT, LineBand
from conformance.motion.arith import acc_time
from gve_fixtures.protocol import SECOND

#: bits per byte on an 8N1 line (spec 2): start, 8 data, stop
BITS_PER_BYTE = 10
#: steps a real target may differ by from the model at a known instant (step placement)
PLACEMENT_STEPS = 1
#: the tick a unit of somebody else's may step, ramp and start on: the manuals time the
#: motion in whole milliseconds (the dwell `T` 1..24 ms) and fix no finer clock
TICK_NS = 1_000_000


def byte_ns(baud: int) -> int:
    """Nanoseconds one byte takes on the line at ``baud`` (8N1)."""
    return round(BITS_PER_BYTE * SECOND / baud)


@dataclass(frozen=True)
class Window:
    """The instants (ns, on the link's clock) between which a frame was processed."""

    lo: int
    hi: int

    @property
    def seconds(self) -> float:
        return (self.hi - self.lo) / SECOND

    def shifted(self, ns: int) -> Window:
        return Window(self.lo + ns, self.hi + ns)


@dataclass(frozen=True)
class Tolerance:
    """The band a check used: the width of the time window (the line's band included),
    steps of placement on top, the line's band (± seconds) and, for a position, the
    steps either side of the model it allowed."""

    seconds: float
    steps: int
    line: float = 0.0
    band: int | None = None

    @property
    def exact(self) -> bool:
        return self.seconds == 0 and self.steps == 0

    def as_dict(self) -> dict:
        return {"seconds": self.seconds, "steps": self.steps,
                **({"line_seconds": self.line} if self.line else {})}

    def __str__(self) -> str:
        if self.band is not None:
            allowed = f"±{self.band} step{'' if self.band == 1 else 's'}"
        else:
            allowed = f"±{self.seconds * 1e3 / 2:.1f} ms"
        return f"{LineBand(self.line)}, {allowed}" if self.line else allowed


def processing_window(sent_at: int, received_at: int, frame_bytes: int, answer_bytes: int,
                      baud: int, *, virtual: bool, paced: bool) -> Window:
    """The window in which the unit processed a frame (see the module's text).

    ``virtual``: the embedded emulator's clock (exact); ``paced``: a line whose bytes take
    their transmission time (a serial port)."""
    b = byte_ns(baud)
    if virtual:
        t = sent_at + frame_bytes * b
        return Window(t, t)
    if paced:
        lo, hi = sent_at + frame_bytes * b, received_at - answer_bytes * b
        if lo <= hi:
            return Window(lo, hi)
    return Window(sent_at, received_at)


def answer_window(sent_at: int, received_at: int, frame_bytes: int, answer_bytes: int,
                  baud: int, *, virtual: bool, paced: bool) -> Window:
    """The window in which the unit sent its answer: the processing instant for most
    frames; for ``H`` and ``W``, which answer when the motion has stopped, later."""
    if virtual:
        t = received_at - answer_bytes * byte_ns(baud)
        return Window(t, t)
    return processing_window(sent_at, received_at, frame_bytes, answer_bytes, baud,
                             virtual=False, paced=paced)


def late_window(sent_at: int, frame_bytes: int, baud: int, round_trip: int, *,
                virtual: bool, paced: bool) -> Window:
    """The processing window of a frame answered late (``H``): after its bytes arrived,
    and no later than the longest round trip observed on the link for frames answered
    at once."""
    b = byte_ns(baud)
    if virtual:
        t = sent_at + frame_bytes * b
        return Window(t, t)
    lo = sent_at + (frame_bytes * b if paced else 0)
    return Window(lo, max(lo, sent_at + round_trip))


def tolerance(window: Window, *, exact: bool, line: LineBand = EXACT,
              band: int | None = None) -> Tolerance:
    """The tolerance a position read in ``window`` is judged with (``exact``: the model's
    placement is the target's own, no step either side; ``line``: the line's band the
    window was widened by; ``band``: the steps either side it allowed)."""
    return Tolerance(window.seconds, 0 if exact else PLACEMENT_STEPS, line.seconds, band)


def step_period(accel: int) -> int:
    """The longest step of a ramp at ``accel`` (steps/s²) that ends at rest, its last:
    how far apart another placement of the same steps may put the instant the motion
    comes to rest (an ``H``'s answer), in ns."""
    return acc_time(0, accel, 1) if accel > 0 else 0


def widened(window: Window, line: LineBand) -> Window:
    """``window`` widened on both sides by the line's band."""
    return Window(*line.widen(window.lo, window.hi))


def since(sample: Window, start: Window) -> Window:
    """The window of the time elapsed from an event in ``start`` (a vector accepted) to
    one in ``sample`` (a position read): both uncertainties add up."""
    return Window(sample.lo - start.hi, sample.hi - start.lo)


def reading_band(a: Window, b: Window, rate: int, *,
                 placement: int = 2 * PLACEMENT_STEPS) -> int:
    """Steps by which two readings of one axis may differ when they were taken in the
    windows ``a`` and ``b`` (each measured from the same motion's start, see
    :func:`since`) while the axis steps at up to ``rate`` per second: the rate times the
    farthest apart the two instants can be, plus the placement step of each real target
    (``placement=0`` when both are exact, e.g. the emulator in virtual time against
    itself)."""
    apart = max(a.hi - b.lo, b.hi - a.lo, 0)
    return math.ceil(rate * apart / SECOND) + placement



def profile_reach(*, starts: int, changes: int, sooner_ns: int, later_ns: int,
                  ramp_ns: int, run_ramps_ns: int = 0) -> tuple[int, int]:
    """How much earlier and how much later (ns) a unit of somebody else's may place a
    motion's events than the reference and still read the manuals: each event (the first,
    each start from rest, each frame that changed the course) a tick of its own either
    way; each start from rest its dwell `T` up to ``sooner_ns`` earlier and ``later_ns``
    later (a reader's T after reset, spec 9 [D], a dwell before every start: the
    course's ``dwell_reach``); and later only, as the reference's profile is the
    quicker: under `VK` a whole ramp each start (`A` along the path, not the dominant
    axis: M84 12.5.4 does not say along which length it accelerates), and a run at a
    speed of its own (`W`) its ramps at `A` to and from its speeds (``run_ramps_ns``: the
    manuals give its speeds, not whether it ramps to them).
    A position read while the motion runs, or near its end, may be ahead or behind by the
    rate times these; the instant the motion ends (an `H`'s or `W`'s answer, RUN or STOP
    read) by the larger."""
    ticks = TICK_NS * (1 + starts + changes)
    return (ticks + starts * sooner_ns,
            ticks + starts * (later_ns + ramp_ns) + run_ramps_ns)
