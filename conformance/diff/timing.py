"""How the two sides of a differential run are held together in time, and how much
their comparison allows for where they cannot be: chosen once per pair.

:class:`Timing` itself is exact (both sides in virtual time): every step starts at the
same instant on both, and nothing is allowed for (an answer's bytes and its timing must
be the same). :class:`RealTime` (a target in real time) lets the reference follow the
target's clock, and widens the positions' band by what the target's latency leaves
uncertain and by the line's band (conformance/link/line_band.py: the round trip the
target's session measured and the example's own).
"""

from __future__ import annotations

import math
from collections.abc import Callable

from conformance.diff.sides import RoundTrip, Side
from conformance.link.line_band import EXACT, LineBand, acted_within, line_band
from conformance.motion.tolerance import PLACEMENT_STEPS
from conformance.protocol.catalogue import classes
from gve_fixtures.protocol import SECOND, St6

#: real time: how long the reference must have been at rest, besides the target's
#: window, for positions to be compared exactly (a target's motion ends when the unit
#: says, the reference's when its model does)
SETTLE_NS = 50_000_000

#: what changes a running motion's course at the instant the unit acts on it (an input
#: set by the rig too): in real time that instant is known only within a latency
_RETIMING = classes(retimes=True) | {"input"}
#: of those, what stops a motion short of its vectors' ends
_STOPPING = classes(stops=True) | {"input"}
#: frames whose answer does not come at once: answered when the motion has stopped, or
#: followed by a restart (their answer's time is no measure of the line's latency)
_DEFERRED = classes(deferred=True) | classes(restart=True)
#: what gives no round trip of the target's line: those, and a rig input (set over the
#: rig's own channel, answered `ok` once done)
_UNTIMED = _DEFERRED | {"input"}
#: readings of the axes' positions (`>` repeats one, read while they may have moved)
_READINGS = classes(position=True) | {">"}
_EMPTIES = classes(empties=True)
#: ST6's bits that tell where a motion is (a vector run, a stop ramp)
_MOTION_BITS = St6.RUN | St6.STOP
#: frames answered when the motion has stopped (H, W)
_AT_REST = classes(deferred=True)
#: the frames whose answer's value is ST6 (F's with its queue bit)
_ST6_READS = ("SR6", "F")


class Timing:
    """Exact timing, both sides in virtual time: each step starts at the same instant
    on both, and a run repeats exactly (a disagreement seen once is seen every time)."""

    exact = True
    repeatable = True

    def __init__(self, target: Side, reference: Side) -> None:
        self.target = target
        self.reference = reference

    def begin(self) -> None:
        """A new example begins."""

    def align(self) -> None:
        """Each step starts at the same instant on both sides: the one behind catches up."""
        self.reference.catch_up(self.target.now)
        self.target.catch_up(self.reference.now)

    def sent(self, at: int) -> None:
        """The target's exchange began at ``at``: the reference acts on the frame then."""
        self.reference.catch_up(at)

    def waiting(self, seconds: float) -> Callable[[], None]:
        """The reference's part of a wait of ``seconds`` the target is about to begin, to
        be done while the target waits (:meth:`waited` then finds it done)."""
        end = self.target.now + round(seconds * 1e9)
        return lambda: self._waited_to(end)

    def waited(self) -> None:
        """The target waited a while: the reference waits as long."""
        self._waited_to(self.target.now)

    def _waited_to(self, end: int) -> None:
        self._follow(end)

    def retimed(self, command: str, target: RoundTrip | None,
                reference: RoundTrip | None = None) -> None:
        """A frame went to both sides, ``target`` and ``reference`` its exchanges (a rig
        input: ``target`` the target rig's, from the command to its `ok`; None: not
        timed)."""

    def allowance(self, command: str, target: RoundTrip, reference: RoundTrip
                  ) -> tuple[bool, int]:
        """For the answers to ``command``: (whether the reading may have been taken while
        the axes moved, how much later in ns the target may have acted than the
        reference on what changed the motion's course)."""
        return False, 0

    def line(self) -> LineBand:
        """How far either side of its exchange the target may have acted on a frame or
        read its counters: nothing in virtual time."""
        return EXACT

    #: how much earlier and how much later (ns) the target may place the motion's events
    #: than the reference under another reading of its profile (set by the pair: it knows
    #: the course); nothing where the target is the reference's own kind
    reach: Callable[[], tuple[int, int]] = staticmethod(lambda: (0, 0))

    def within(self, command: str, body: str, kind: str, target: RoundTrip,
               reference: RoundTrip, rate: int, heading: list[int],
               reach: tuple[int, int]) -> bool:
        """Whether a difference of ``kind`` (to ``body``, of ``command``) lies within what
        another profile of the same motion reads (:class:`Readings`); never where the
        comparison is the reference's own. ``heading``: each axis's direction in the last
        vector that moved it; ``reach``: how much earlier and later the target may place
        the motion's events, this frame's run included (the pair's ``reach``)."""
        return False

    def _follow(self, instant: int) -> None:
        """The reference waits until ``instant`` on the target's clock (if it is behind)."""
        self.reference.wait(max(0, instant - self.reference.now) / 1e9)


class RealTime(Timing):
    """A target in real time: the reference acts on a frame when the target's exchange
    began, the target somewhere within its latency (the largest an immediate answer took
    in the sequence so far). A frame (or rig input) that changes a running motion's
    course makes the readings while it runs uncertain by the rate times that latency;
    one that stops it short (H, INTA written, an input) the positions at rest too, until
    the vector it cut has run to its end — for good once D or K threw the rest away. A
    disagreement seen once may be that run's timing, not the target."""

    exact = False
    repeatable = False

    def __init__(self, target: Side, reference: Side) -> None:
        super().__init__(target, reference)
        self.begin()

    def begin(self) -> None:
        #: when the reference was first seen at rest (None: moving)
        self.idle_since: int | None = 0
        self.latency_ns = self.slack_ns = self.cut_ns = 0
        self.trips: list[int] = []       # the target's round trips, answered at once (ns)
        self.lost = False

    def align(self) -> None:
        self.reference.catch_up(self.target.now)

    def sent(self, at: int) -> None:
        pass

    def _waited_to(self, end: int) -> None:
        # looked at before the wait's end too: a motion that ended early in a long wait
        # is at rest for a read right after it
        self._follow(end - 2 * SETTLE_NS)
        self._watch_reference()
        self._follow(end)

    def retimed(self, command: str, target: RoundTrip | None,
                reference: RoundTrip | None = None) -> None:
        if target is not None and command not in _UNTIMED and target.answer:
            self.latency_ns = max(self.latency_ns, target.received_at - target.sent_at)
            self.trips.append(target.received_at - target.sent_at)
        if command in _EMPTIES and self.cut_ns:
            self.lost = True
        if command in _RETIMING and self.idle_since is None:
            late = self._late(command, target, reference)
            self.slack_ns += late
            if command in _STOPPING:
                self.cut_ns += late

    def _late(self, command: str, target: RoundTrip | None,
              reference: RoundTrip | None) -> int:
        """How much later than the reference the target may have acted on a frame (or a
        rig input): the latency, or as late as its own answer came, less what it takes
        by the reference's answer when it answers once done (H): the line at that frame
        (or the rig's channel) is no measure of the line before it."""
        if target is None or not target.answer:
            return self.latency_ns
        takes = 0
        if command in _DEFERRED:
            if reference is None or not reference.answer:
                return self.latency_ns
            takes = reference.received_at - reference.sent_at
        return acted_within(target.sent_at, target.received_at, takes, self.latency_ns)

    def allowance(self, command: str, target: RoundTrip, reference: RoundTrip
                  ) -> tuple[bool, int]:
        self._watch_reference()
        moving = command in _READINGS and (command == ">"
                                           or self._moving_near(target, reference))
        return moving, self.cut_ns + (self.slack_ns if moving else 0)

    def line(self) -> LineBand:
        return line_band(self.target.link.round_trip, [t / 1e6 for t in self.trips])

    def _watch_reference(self) -> None:
        """Note when the reference was first seen at rest (after each step; a late note
        only makes the comparison more lenient); at rest and not interrupted, every
        vector has reached its end, and when they were acted on no longer shows."""
        rig = self.reference.link.rig
        st6 = 0xFF if rig is None else int(rig.state()["status"][6], 16)
        if st6 & St6.RUN:
            self.idle_since = None
            return
        if self.idle_since is None:
            self.idle_since = self.reference.now
        if not st6 & St6.INTA:
            self.slack_ns = 0
            if not self.lost:
                self.cut_ns = 0

    def _moving_near(self, target: RoundTrip, reference: RoundTrip) -> bool:
        """Whether the reading may have been taken while the axes moved on either side:
        the reference had not been at rest for as long as the target's window is wide
        (the target may have processed the frame that much later or earlier)."""
        if self.idle_since is None:
            return True
        width = target.received_at - target.sent_at
        return reference.sent_at - self.idle_since < 2 * width + SETTLE_NS


class Readings(Timing):
    """Both sides in virtual time, the target somebody else's: as exact as :class:`Timing`,
    and it watches the reference's motion (when RUN or STOP last changed, whether a frame
    cut it short) so that a difference another profile of the same motion explains is
    told apart from one no reading explains (:meth:`within`). The manuals fix V, A, B,
    `$` and T, where a motion ends at rest and in what order things happen; not the tick a
    unit steps, ramps and starts on, where the dwell falls, nor along which length A
    accelerates under VK (conformance/motion/tolerance.py: ``profile_reach``)."""

    def __init__(self, target: Side, reference: Side) -> None:
        super().__init__(target, reference)
        self.begin()

    def begin(self) -> None:
        self.st6 = 0
        self.edge_at: int | None = None     # when RUN or STOP last changed
        self.cut = self.lost = False        # a frame stopped the motion short of its end

    def _waited_to(self, end: int) -> None:
        # looked at the reach before the wait's end too: an end within it is near the read
        self._follow(end - max(self.reach()))
        self._watch()
        self._follow(end)
        self._watch()

    def retimed(self, command: str, target: RoundTrip | None,
                reference: RoundTrip | None = None) -> None:
        if command in _STOPPING and self.st6 & St6.RUN:
            self.cut = True
        if command in _EMPTIES and self.cut:
            self.lost = True
        self._watch()

    def _watch(self) -> None:
        rig = self.reference.link.rig
        if rig is None:
            return
        st6 = int(rig.state()["status"][6], 16)
        if (st6 ^ self.st6) & _MOTION_BITS:
            self.edge_at = self.reference.now
        self.st6 = st6
        if not st6 & (St6.RUN | St6.INTA) and not self.lost:
            self.cut = False               # every vector ran to its end after all

    def within(self, command: str, body: str, kind: str, target: RoundTrip,
               reference: RoundTrip, rate: int, heading: list[int],
               reach: tuple[int, int]) -> bool:
        self._watch()
        ahead, behind = reach
        longest = max(reach)
        ended = self.edge_at is not None and self.reference.now - self.edge_at <= longest
        if kind == "position":
            if not (ended or self.cut or self.st6 & St6.RUN):
                return False               # at rest, where every reading ends alike
            return _numbers_within(target, reference, heading,
                                   *(math.ceil(rate * ns / SECOND) + PLACEMENT_STEPS
                                     for ns in (ahead, behind)))
        if kind == "timing":
            late = (target.received_at - target.sent_at) - (reference.received_at
                                                             - reference.sent_at)
            return command in _AT_REST and abs(late) <= longest
        if kind == "data":
            # RUN or STOP read as the motion ends: near an end seen, or in a stop ramp
            # (another tick ends it sooner)
            return body in _ST6_READS and (ended or bool(self.st6 & St6.STOP)) \
                and _st6_motion_only(target, reference)
        return False


def _numbers_within(target: RoundTrip, reference: RoundTrip, heading: list[int],
                    ahead: int, behind: int) -> bool:
    """Whether each axis of the target's reading is at most ``ahead`` steps farther along
    its direction than the reference's and at most ``behind`` short of it (an axis that
    no vector moved: ``ahead`` either way)."""
    try:
        xs = [int(v) for v in target.response.values]
        ys = [int(v) for v in reference.response.values]
    except (AttributeError, ValueError):
        return False
    if len(xs) != len(ys):
        return False
    headings = [*heading, *[0] * len(xs)]
    for x, y, h in zip(xs, ys, headings, strict=False):
        lead = (x - y) * h if h else abs(x - y)
        if lead > ahead or -lead > (behind if h else ahead):
            return False
    return True


def _st6_motion_only(target: RoundTrip, reference: RoundTrip) -> bool:
    """Two reads of ST6 (`SR6`, `F`) that differ in RUN or STOP only."""
    try:
        a, b = (int(x.response.values[0], 16) for x in (target, reference))
    except (AttributeError, IndexError, ValueError):
        return False
    return bool(a ^ b) and not (a ^ b) & ~_MOTION_BITS


def timing_for(target: Side, reference: Side) -> Timing:
    """Exact when both sides are in virtual time (the target somebody else's: exact, and
    watched for what another profile of the motion reads), else real time."""
    if not (target.virtual and reference.virtual):
        return RealTime(target, reference)
    return Timing(target, reference) if target.target.info.strict else Readings(target,
                                                                                reference)
