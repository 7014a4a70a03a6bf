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

from conformance.diff.sides import RoundTrip, Side
from conformance.link.line_band import EXACT, LineBand, acted_within, line_band
from conformance.protocol.catalogue import classes
from gve_fixtures.protocol import St6

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

    def waited(self) -> None:
        """The target waited a while: the reference waits as long."""
        self._follow(self.target.now)

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

    def waited(self) -> None:
        # looked at before the wait's end too: a motion that ended early in a long wait
        # is at rest for a read right after it
        self._follow(self.target.now - 2 * SETTLE_NS)
        self._watch_reference()
        self._follow(self.target.now)

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


def timing_for(target: Side, reference: Side) -> Timing:
    """Exact when both sides are in virtual time, else real time."""
    kind = Timing if target.virtual and reference.virtual else RealTime
    return kind(target, reference)
