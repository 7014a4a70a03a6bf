"""The run-wide guard on a real unit: every frame is judged here before it is sent,
whoever sends it (a case, a machine, a golden replay's raw bytes, the diff runner, the
session itself): once per exchange, when a link is about to write it (:meth:`Guard.admit`).

Real units are machines with spindles. The guard refuses (:class:`SafetyStop`, the case
ends COULD-NOT-TEST) a frame that could take an axis beyond ``max_travel`` full steps
from where the run began (the :class:`~conformance.link.envelope.Envelope` keeps that for
the whole run), `J`, `W` and EEPROM writes without ``allow_destructive``, an EEPROM write
to a byte the session did not back up, and motion or destructive frames for an address
that is not the unit's. It raises :class:`~conformance.link.signals.Interrupted`
before any frame once Ctrl-C was pressed (except the session's `H`, `D` and
restorations), :class:`TargetNotResponding` once the unit stopped answering (its
:class:`~conformance.link.liveness.Liveness`), and :class:`UnitRestarted` in the case
during which the unit restarted by itself.

What an exchange showed is not told to the guard: the link tells it to the objects that
follow the unit, each the owner of its state, which the guard reads when it judges: the
unit's :class:`~conformance.link.bookkeeping.Bookkeeping` (where the axes may be, the
envelope, the restarts seen), its liveness (frames unanswered), and the link's view of
the wire (protocol/view.py). How long answers may take is the unit's
:class:`~conformance.link.answer_time.AnswerTime`.

Public interface (docs/suite.md, "The session and its guard")::

    guard.admit(frames, summed)          # a link's frames about to go out: judged once
    guard.followers()                    # who the link tells each exchange
    guard.check(body, address)           # before sending: raises SafetyStop / Interrupted
    guard.check_frames(frames, summed)   # the same for raw bytes, framed as a unit would
    guard.accepted(body, response, address)   # frames sent otherwise than by a link
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass

from conformance.link.answer_time import AnswerTime
from conformance.link.body import Body, number
from conformance.link.bookkeeping import Bookkeeping, Depth, shallow, steps
from conformance.link.envelope import EMPTY, INF, Envelope, Outcome, Span
from conformance.link.framing import HostFrame, Response
from conformance.link.ledger import EepromLedger
from conformance.link.liveness import Liveness, TargetNotResponding
from conformance.link.signals import Interrupted, StopSignals
from conformance.link.stops import SafetyStop
from conformance.protocol.catalogue import catalogue, classes, eeprom_width
from conformance.protocol.view import View
from gve_fixtures.profile import Profile


class BeyondEnvelope(SafetyStop):
    """A motion frame after which an axis could leave the envelope (a machine that draws
    its vectors may draw another instead: :meth:`Guard.fits`)."""


#: frames that can start an axis moving (and so ask the operator first)
MOTION = classes(motion=True)
#: frames that change what outlives the run: restart, reference run, EEPROM
DESTRUCTIVE = classes(destructive=True)
#: frames that set the checksum mode, and so how the unit reads the frames after them
_SUMMING = classes(summing=True)
#: frames that set no axis moving, whatever the unit is, and those whose answer tells
#: where the axes are
_MOVE_NOTHING = classes(motion=False, own_speed=False, resumes=None, destructive=False,
                        eeprom=0)
_POSITION_READS = classes(position=True)


def after_a_read(names: Sequence[str], read: bool) -> tuple[bool, bool]:
    """Frames of commands ``names`` told ahead, ``read``: a position read told before
    them (its answer may move the axes anywhere in the bookkeeping's eyes): whether they
    may be told (after a read, only what sets nothing moving), and whether a read is
    told before the frames after them."""
    if read and not all(name in _MOVE_NOTHING for name in names):
        return False, True
    return True, read or any(name in _POSITION_READS for name in names)

#: what a command sets moving again, by name: "queue" or "save"
_RESUMES = {n: c.resumes for n, c in catalogue().items() if c.resumes}


@dataclass(frozen=True)
class Admitted:
    """What the guard said of frames it let out: how long the last one's answer may
    take (None: at once), and whether they are the session's own frames or its `H` and
    `D` after Ctrl-C (``own``, ``urgent``), which a signal that comes before they are
    written keeps off the line or not (:meth:`StopSignals.bars`)."""

    answer_seconds: float | None = None
    own: bool = False
    urgent: bool = False


def _readings(frames: list[HostFrame], summed: bool | None,
              address: int) -> Iterator[tuple[str, int]]:
    """Each frame's body in every reading the unit may give it (``summed``: in checksum
    mode its last field is its checksum, spec 6; None, and after a frame that may set
    the mode: with and without), with the address it is for."""
    for f in frames:
        bodies = f.bodies(summed)
        for body in bodies:
            yield body, f.address if f.address is not None else address
        if any(Body.parse(body).name in _SUMMING for body in bodies):
            summed = None


class Guard:
    """One real unit's run-wide guard (see the module's docstring). It judges frames and
    owns the EEPROM ledger and the run's stop signals; it reads its followers (the
    bookkeeping, which owns the envelope, and the liveness) and the answer times."""

    def __init__(self, profile: Profile, address: int, *, max_travel: int,
                 allow_destructive: bool, interrupts: StopSignals | None = None) -> None:
        self.profile = profile
        self.address = address
        self.max_travel = max_travel
        self.allow_destructive = allow_destructive
        self.interrupts = interrupts or StopSignals()
        micro = profile.microstep
        self.scale = profile.position_scale               # counter units per full step
        envelope = Envelope(
            len(profile.axes), self._limit(max_travel),
            tuple(micro.factors.values()) if micro else (1,),
            micro.factors[micro.reset_mode] if micro else 1)
        self.addresses = {address} | ({profile.spindle.address} if profile.spindle else set())
        self.eeprom = EepromLedger()
        self.before_motion: Callable[[], bool | None] | None = None
        self.motion_confirmed: bool | None = None
        #: whether the unit is there (frames in a row unanswered): told by the links
        self.liveness = Liveness(self._restart_ms(profile), frozenset(self.addresses))
        #: where the axes may be, the restarts seen: told by the links
        self.bookkeeping = self._bookkeeping(envelope)
        #: how long answers may take (`H` and `W` answer when their motion ends)
        self.times = AnswerTime(profile, envelope)
        self._own = Depth()                       # inside the session's own frames
        self._emergency = Depth()
        self._hands_on = Depth()                  # a technician's hand step is open

    def _limit(self, max_travel: int) -> float:
        """The envelope's reach either side, in counter units."""
        return max_travel * self.scale

    def _restart_ms(self, profile: Profile) -> float | None:
        """How long the unit takes to restart (its silence meanwhile is waited out)."""
        return profile.restart_ms

    def _bookkeeping(self, envelope: Envelope) -> Bookkeeping:
        return Bookkeeping(self.profile, self.address, envelope, self.liveness,
                           frozenset(self.addresses))

    def followers(self) -> tuple[Bookkeeping, Liveness]:
        """Those a link tells each exchange it observed, in this order (the bookkeeping
        books the frames, then the liveness counts the answer)."""
        return self.bookkeeping, self.liveness

    # -- what the bookkeeping, the liveness and the answer times hold ---------------------
    envelope = property(lambda self: self.bookkeeping.envelope)
    view = property(lambda self: self.bookkeeping.view)
    packet_open = property(lambda self: self.bookkeeping.packet_open)
    lost = property(lambda self: self.bookkeeping.lost)
    restarts = property(lambda self: self.bookkeeping.restarts)
    untracked = property(lambda self: self.bookkeeping.untracked)
    since = property(lambda self: self.bookkeeping.since)
    recentred = property(lambda self: self.bookkeeping.recentred)
    keep_held = property(lambda self: self.bookkeeping.keep_held)
    responding = property(lambda self: self.liveness.responding)

    def accepted(self, body: str, response: Response | None,
                 address: int | None = None) -> None:
        """Book a frame sent otherwise than by a link (a host's, relayed) with its answer
        (None: none seen)."""
        self.bookkeeping.accepted(body, response, address)

    def book_any(self, body: str, address: int | None = None) -> None:
        self.bookkeeping.book_any(body, address)

    def restarted(self) -> None:
        """The unit restarted by other means than `J` (a test rig's power cycle)."""
        self.bookkeeping.restarted()

    def recentre(self) -> None:
        self.bookkeeping.recentre()

    def locate(self, physical: dict[int, int], counters: dict[int, int]) -> None:
        self.bookkeeping.locate(physical, counters)

    def whereabouts(self) -> str:
        return self.bookkeeping.whereabouts()

    def where(self, axis: int) -> str:
        return self.bookkeeping.where(axis)

    def doubt_rest(self) -> None:
        self.bookkeeping.doubt_rest()

    def excursion(self) -> list[tuple[float, float]]:
        return self.bookkeeping.excursion()

    def stop_seconds(self) -> float:
        return self.times.stop_seconds()

    def answer_seconds(self, body: str) -> float | None:
        return self.times.answer_seconds(body)

    # -- who is sending ----------------------------------------------------------------------
    def own_frames(self) -> Depth:
        """The session's own frames (known state, snapshot, restorations): after Ctrl-C
        these still go out, except motion."""
        return self._own

    def emergency(self) -> Depth:
        """`H` and `D` after Ctrl-C: the frames that go out before anything else."""
        return self._emergency

    def unmoved(self) -> Depth:
        """Position reads the session takes at rest with nothing sent that moves since the
        bookkeeping last knew where the axes are (right after `N`): a counter read
        otherwise is a counter that did not take the set, never motion."""
        return self.bookkeeping.unmoved

    def hands_on(self) -> Depth:
        """A technician's hand step is open (a prompt waits for them): no motion until it
        is answered, whoever sends."""
        return self._hands_on

    # -- before a frame ----------------------------------------------------------------------
    def check_idle(self) -> None:
        """Raise if the run must stop here (Ctrl-C; a target that stopped answering):
        before every frame and every wait of a case."""
        if self._emergency:
            return
        if self.interrupts.bars(own=bool(self._own)):
            raise Interrupted
        self.liveness.check()
        self.bookkeeping.tell_restart(own=bool(self._own))

    def check(self, body: str, address: int | None = None) -> None:
        """Raise if the frame ``body`` for ``address`` may not be sent now."""
        self.check_idle()
        if self._emergency:
            return
        command = Body.parse(body)
        address = self.address if address is None else address
        if address not in self.addresses:
            if command.name in MOTION | DESTRUCTIVE:
                raise SafetyStop(f"{body} for address {address}: another unit may be on "
                                 "the line there; the suite moves and writes only its own")
            return
        if command.name in MOTION and self._hands_on:
            raise SafetyStop(f"{body}: motion refused while a hand step is open (the "
                             "technician's hands may be on the machine)")
        if command.name in DESTRUCTIVE:
            self._check_destructive(body, command)
        if command.name in MOTION:
            self._check_motion(body, command)

    def fits(self, body: str) -> bool:
        """Whether the motion frame ``body`` keeps every axis in the envelope now (always
        on the emulator); other reasons not to send it still raise."""
        try:
            self.check(body)
        except BeyondEnvelope:
            return False
        return True

    def admit(self, frames: list[HostFrame], summed: bool | None, *,
              judged: bool = False) -> Admitted:
        """Judge the frames a link is about to write (:meth:`check_frames`; ``judged``:
        judged already, as they were told a co-simulator ahead, so only whether the run
        stops here) and say what the link needs of them: one question per exchange."""
        if judged:
            self.check_idle()
            # what judging them booked on the copy, the run's guard books now: the EEPROM
            # bytes they may write, in every reading they were judged in
            for body, address in _readings(frames, None, self.address):
                self._eeprom_written(body, address)
        else:
            self.check_frames(frames, summed)
        body = frames[-1].bodies(summed)[0] if frames else ""
        return Admitted(self.answer_seconds(body) if body else None, bool(self._own),
                        bool(self._emergency))

    def check_frames(self, frames: list[HostFrame], summed: bool | None) -> None:
        """:meth:`check` raw frames as the unit reads them: in checksum mode (``summed``)
        a frame's last field is its checksum, not a component (spec 6); when the mode is
        not known (None), and after a frame that may set it, every reading (with and
        without a trailing checksum)."""
        for body, address in _readings(frames, summed, self.address):
            self.check(body, address)

    def _eeprom_written(self, body: str, address: int) -> None:
        """Book the EEPROM bytes the frame ``body`` judged already may write."""
        command = Body.parse(body)
        width = eeprom_width(command.name)
        if address in self.addresses and width:
            # (one whose bytes cannot be told is refused: it was never told)
            self.eeprom.write(self._eeprom_bytes(command, width))

    def _check_destructive(self, body: str, command: Body) -> None:
        if not self.allow_destructive:
            raise SafetyStop(f"{body} restarts the unit, runs to a switch or writes EEPROM: "
                             "needs --allow-destructive")
        width = eeprom_width(command.name)
        if width:
            touched = self._eeprom_bytes(command, width)
            lost = [a for a in touched if not self.eeprom.backed_up(a)] if touched else [-1]
            if lost:
                shown = "?" if lost == [-1] else " ".join("%02X" % a for a in lost)
                raise SafetyStop(f"{body}: EEPROM {shown} not backed up, so not written")
            self.eeprom.write(touched)

    def _eeprom_bytes(self, command: Body, width: int) -> list[int]:
        start = number(command.params.split(",")[0], 16)
        if not start.exact:
            return []
        size = self.profile.eeprom.size
        return [(int(start.lo) + i) % size for i in range(width)]

    def farthest(self, body: str) -> float:
        """How far (full steps) from where the run began an axis could be once the frame
        ``body`` went out: the envelope it needs now (inf: it cannot be bounded)."""
        command = Body.parse(body)
        reach = self._reach(command) if command.name in MOTION else self.envelope.reach()
        return max(max(-steps(s.lo, self.scale), steps(s.hi, self.scale)) for s in reach)

    def _reach(self, command: Body) -> list[Span]:
        event = self.bookkeeping.event(command, Outcome.UNCLEAR, None)
        return self.envelope.would_reach(event) if event else self.envelope.reach()

    def _check_motion(self, body: str, command: Body) -> None:
        e = self.envelope
        reach = self._reach(command)
        axis = e.outside(reach)
        if axis is not None:
            span = reach[axis]
            raise BeyondEnvelope(
                f"{body}: axis {self.profile.axes[axis]} could reach "
                f"{steps(span.lo, self.scale)}..{steps(span.hi, self.scale)} full steps "
                f"from where the run began, beyond the envelope ±{self.max_travel}")
        # G and a write of ST6 resume the queue, R the save: they move only when something waits
        resumes = _RESUMES.get(command.name)
        waiting = (resumes == "queue" and any(p != EMPTY for p in e.queue)) or (
            resumes == "save" and ((e.saved is not None and e.save_moves)
                                   or e.rerun is not None))
        if reach != e.reach() or waiting:
            if self.interrupts.stopped:
                raise SafetyStop(f"{body}: no motion after Ctrl-C")
            if self.lost:
                raise SafetyStop(f"{body}: no motion: {self.lost}")
            self._confirm_motion(body)

    def _confirm_motion(self, body: str) -> None:
        if self.motion_confirmed is None:
            ask = self.before_motion
            self.motion_confirmed = True if ask is None else ask() is not False
        if not self.motion_confirmed:
            raise SafetyStop(f"{body}: motion was not confirmed")

    # -- frames told ahead ------------------------------------------------------------------
    def told_ahead(self, bodies: Sequence[str], address: int) -> list[str]:
        """The first of ``bodies`` that may be told a port ahead (a co-simulator's
        `batch`): a port told them runs them before the run's guard judges any, so each is
        judged first on a copy (:meth:`ahead`) as though the ones before got any answer.
        The first refused ends them, and after a position read, whose answer may move the
        axes anywhere in the bookkeeping's eyes, only frames that set nothing moving
        follow."""
        trial = self.ahead()
        admitted: list[str] = []
        read = False
        for body in bodies:
            name = Body.parse(body).name            # SW6 apart from the other SW
            may, after = after_a_read([name], read)
            if not may:
                break
            try:
                trial.check(body, address)
            except (SafetyStop, Interrupted, TargetNotResponding):
                break
            trial.book_any(body, address)
            read = after
            admitted.append(body)
        return admitted

    def ahead(self) -> Guard:
        """A copy of this guard on which frames told ahead of their sending (a
        co-simulator's `batch`) are judged one after the other, each booked with
        :meth:`book_any` once judged: a frame the copy lets through, this guard lets
        through when it comes to be sent, whatever the unit answered the ones before it.
        The copy asks nobody (motion not confirmed yet is refused on it) and changes
        nothing here."""
        trial = shallow(self)
        trial.bookkeeping = self.bookkeeping.copy(self.liveness)
        trial.eeprom = self.eeprom.copy()
        trial.times = AnswerTime(self.profile, trial.envelope)
        if self.motion_confirmed is None and self.before_motion is not None:
            trial.before_motion = lambda: False
        return trial

class EmulatorGuard(Guard):
    """The embedded emulator's guard: every link is a fresh unit and nothing outlives the
    run, so no frame is refused or booked; it still stops the run for Ctrl-C and for a
    unit that stopped answering."""

    def __init__(self, profile: Profile, address: int,
                 interrupts: StopSignals | None = None) -> None:
        super().__init__(profile, address, max_travel=0, allow_destructive=True,
                         interrupts=interrupts)

    def _limit(self, max_travel: int) -> float:
        return INF

    def check(self, body: str, address: int | None = None) -> None:
        self.check_idle()

    def _restart_ms(self, profile: Profile) -> float | None:
        return None              # a fresh unit per link: its silence is no restart's

    def _bookkeeping(self, envelope: Envelope) -> Bookkeeping:
        return _Unbooked(self.profile, self.address, envelope, self.liveness,
                         frozenset(self.addresses))


class _Unbooked(Bookkeeping):
    """The emulator's bookkeeping: nothing a frame does outlives its link."""

    def accepted(self, body: str, response: Response | None, address: int | None = None,
                 view: View | None = None) -> None:
        return None

    def restarted(self) -> None:
        return None
