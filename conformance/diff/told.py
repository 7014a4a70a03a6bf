"""Frames told a co-simulator ahead in a differential run: a sequence's frames in one
exchange (its `batch`, docs/cosim.md) instead of one round trip each.

Both sides run in virtual time and a sequence stops at its first disagreement, so until
then the target answers each frame when the reference does and each frame starts at the
same instant on both. The reference is therefore run ahead over the frames coming
(a fill as far as the reference takes it), and the target is told those the run's guard
can judge now, whatever the answers before them (conformance/link/ahead.py). The target's
frames are then sent as they come, each answered from what the simulator ran, and
compared with the reference's answer to it.

A frame told is on the target's line already: where the sequence stops early (a
disagreement, both answers allowed), the frames it ran are sent all the same, uncompared,
so that the guard books what the unit did; when the run is cut short by a signal or a
target gone silent, they are booked as though they got any answer. Where the target
answered alike but not at the reference's instant (the index counted from each side's
start), the frames told after it began elsewhere than on the reference: the run is
redone frame by frame (:attr:`Teller.drifted`).
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable
from dataclasses import dataclass

from conformance.diff.index_base import QUERIES
from conformance.diff.labels import command_of
from conformance.diff.sides import RoundTrip, Side
from conformance.diff.steps import FILL, FRAME, STATE, Step
from conformance.link.ahead import Ahead
from conformance.link.stops import SafetyStop
from conformance.protocol.catalogue import classes
from conformance.protocol.framer import HostFramer
from gve_fixtures.protocol import ErrorCode

#: frames after which none is told in the same exchange: they change how the host frames
#: (the checksum mode) or restart the unit, or their answers may be alike without being
#: the same bytes (the index), so the frames after them may start elsewhere on each side
ENDS = classes(summing=True) | classes(restart=True) | QUERIES
#: the most frames told in one exchange
MOST = 64


@dataclass
class Told:
    """A frame the reference has answered ahead of the target."""

    data: bytes
    step: Step
    reference: RoundTrip | None = None      # (None until the reference has run it)
    ended: str = ""                # the reference gone silent for good at this frame
    ran: bool = False              # the target ran it when told (else it goes out live)


def tellable(step: Step) -> bool:
    """A frame that may be told ahead: one line of answer or none, whole, not stalled
    (one that is due no answer only last: a unit that answers it all the same stops its
    part of the exchange at the answer, not where the listening ends)."""
    return ((step.kind == FRAME or (step.kind == FILL and step.times > 0))
            and step.lines == 1 and step.stall is None and not step.raw)


def _silent(told: Told) -> RoundTrip:
    """What a reference gone silent gave a frame: nothing."""
    return RoundTrip(told.data, b"", 0, 0, None, told.step.lines)


class Teller:
    """One example's frames told ahead, for the target ``side``; ``refer`` runs a step's
    frame on the reference (its exchange, and why the sequence ends there: "" to go on)."""

    def __init__(self, side: Side, steps: list[Step],
                 refer: Callable[[Step, bytes], tuple[RoundTrip, str]]) -> None:
        self.side = side
        self.steps = steps
        self.refer = refer
        self.queue: deque[Told] = deque()
        #: the target answered alike at another instant than the reference within frames
        #: told ahead: this run's comparisons after it are not the sequence's
        self.drifted = False

    def tell(self, place: int, repeat: int) -> None:
        """Tell the target the frames from frame ``repeat`` of step ``place`` on that the
        guard lets through (at least two), and run the reference over them while the
        target runs them. A fill is run on the reference as it is planned: how many of
        its frames go is the reference's answers' (until the queue is full)."""
        link = self.side.link
        if not (self._more(place, repeat) and link.takes_ahead):
            if self._read_after(place):
                self.side.state_next()
            return
        eager = self.steps[place].kind == FILL
        ahead, planned, last = self._plan(place, repeat, eager)
        if planned and self._read_after(last):
            self.side.state_next()
        if len(planned) < 2 and not eager:
            return          # one frame: it goes out live, the reference run meanwhile
        launched: bool | None = None        # (None: being told, its write maybe gone)
        try:
            launched = ahead.launch()
            if not eager:
                self._refer_all(planned)     # while the target runs them
            ran = ahead.landed() if launched else 0
        except BaseException:
            # told, a simulator that broke the protocol midway, or a run cut short
            # meanwhile, may have run any of them (untold, none went out)
            if launched is not False:
                for told in planned:
                    told.ran = True
                self.forget(planned)
            raise
        for i, told in enumerate(planned):
            told.ran = i < ran
        self.queue.extend(planned)

    def _plan(self, place: int, repeat: int, eager: bool) -> tuple[Ahead, list[Told], int]:
        """The frames from frame ``repeat`` of step ``place`` on that the guard lets
        through, each run on the reference as it is planned where ``eager`` (a fill, and
        what follows it); with the list they were admitted to and the last step's place."""
        link = self.side.link
        ahead, planned, last = Ahead(link), [], place
        while place < len(self.steps) and len(planned) < MOST:
            step = self.steps[place]
            if not tellable(step) or (step.kind == FILL and not eager):
                break
            data = step.frame_bytes(self.side.target.address, link.checksums)
            if not ahead.admit(data, self.side.awaited(data, step.body, step.answer)):
                break
            last = place
            told = Told(data, step)
            planned.append(told)
            if eager:
                self._refer(told, ahead)
            if told.ended or not step.answer or command_of(step.body) in ENDS:
                break
            if eager and step.kind == FILL and repeat + 1 < step.times \
                    and told.reference.code == ErrorCode.OK:
                repeat += 1
            else:
                place, repeat = place + 1, 0
        return ahead, planned, last

    def _refer_all(self, planned: list[Told]) -> None:
        """The frames planned run on the reference in turn; once it has gone silent for
        good, the rest get nothing (the sequence ends at that frame)."""
        ended = ""
        for told in planned:
            if ended:
                told.reference, told.ended = _silent(told), ended
            else:
                self._refer(told, None)
                ended = told.ended

    def _refer(self, told: Told, ahead: Ahead | None) -> None:
        """A told frame run on the reference; ``ahead``: the list it was admitted to last,
        told when the target's answer is due (the reference's own)."""
        step = told.step
        told.reference, told.ended = self.refer(step, told.data)
        reference = told.reference
        if ahead is not None and step.answer and reference.answer:
            # the target answers when the reference did, or differs: then its frames
            # told after it need not run
            ahead.due(reference.received_at - reference.sent_at)

    def _read_after(self, place: int) -> bool:
        """Whether the rig's state is read right after the frame of step ``place`` (a
        rig read next, or the sequence's end: what the rig sees then)."""
        if self.steps[place].kind != FRAME:
            return False
        return place + 1 == len(self.steps) or self.steps[place + 1].kind == STATE

    def _more(self, place: int, repeat: int) -> bool:
        """Whether a second frame may follow the one at ``place``: worth telling."""
        step = self.steps[place]
        if not (tellable(step) and step.answer):
            return False
        if step.kind == FILL and repeat + 1 < step.times:
            return True
        return place + 1 < len(self.steps) and tellable(self.steps[place + 1])

    def take(self, data: bytes) -> Told | None:
        """The next frame told, to be sent as ``data`` (None: none waits)."""
        if not self.queue:
            return None
        if self.queue[0].data != data:       # (the frames are made alike: never)
            self.drifted = True
            self.forget()
            return None
        return self.queue.popleft()

    def check(self, told: Told, target: RoundTrip | None) -> None:
        """The target's exchange of a frame the reference answered ahead must have begun
        at the reference's instant: else what the reference answered is not what it
        would have, and the run is redone frame by frame."""
        if target is None or target.sent_at != told.reference.sent_at:
            self.drifted = True

    def finish(self) -> None:
        """The sequence has stopped: the frames the target ran and nobody sent go out now,
        as told (uncompared), so that the guard books them with their answers; one it
        refuses (it cannot, having judged them ahead) is booked as though answered
        anyhow, with the rest."""
        while self.queue:
            told = self.queue.popleft()
            if not told.ran:
                continue
            try:
                self.side.exchange(told.data, lines=told.step.lines, answer=told.step.answer,
                                   body=told.step.body)
            except SafetyStop:
                self.forget([told])
                return
            except BaseException:
                self.forget([told])
                raise

    def forget(self, extra: list[Told] | None = None) -> None:
        """The run was cut short: the frames the target ran and nobody sent are booked as
        though they got any answer (the guard must count what the unit may have done)."""
        guard = self.side.link.guard
        for told in [*(extra or []), *self.queue]:
            if told.ran:
                for f in HostFramer().frames(told.data):
                    for body in f.bodies(None):
                        guard.book_any(body, f.address)
        self.queue.clear()
