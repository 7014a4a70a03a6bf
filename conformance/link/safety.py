"""The run-wide guard on a real unit: every frame is judged here before it is
sent and booked here after its answer, whoever sends it (a case, a machine, a golden
replay's raw bytes, the diff runner, the session itself).

Real units are machines with spindles. The guard refuses (:class:`SafetyStop`, the case
ends COULD-NOT-TEST) a frame that could take an axis beyond ``max_travel`` full steps
from where the run began (the :class:`~conformance.link.envelope.Envelope` keeps that for
the whole run), `J`, `W` and EEPROM writes without ``allow_destructive``, an EEPROM write
to a byte the session did not back up, and motion or destructive frames for an address
that is not the unit's. It raises :class:`~conformance.link.signals.Interrupted`
before any frame once Ctrl-C was pressed (except the session's `H`, `D` and
restorations), and :class:`TargetNotResponding` after a few frames in a row got no
answer.

A unit that restarts by itself is seen in what it reads back (the envelope's
:meth:`~conformance.link.envelope.Envelope.observe`): the power-on counters (spec 9)
where the frames put the axes elsewhere, after frames went unanswered (spec 2: bytes are
lost while a unit restarts) or with the other power-on facts read since (ST0..ST6 00,
the index counting from 0, the checksum mode off: spec 9); counters 0 alone are no
restart (a unit that moved by a wrong amount may read them). The case in which it is seen ends
(:class:`UnitRestarted`), the restart is kept in :attr:`Guard.restarts` for the
report, and where the axes are is no longer known unless they cannot have moved since
they last were: then no motion frame goes out (:attr:`Guard.lost`) until the session
locates them again (:meth:`Guard.locate`).

Other counters than the frames allow are no restart: the unit moved by another amount
than the frames say (a fault a case judges), or the axes were moved by other means. The
answer goes back to the case, which judges what it read; the guard keeps what it saw
with the frames that led there (:attr:`Guard.untracked`) and, as after a restart, lets
no motion frame out until the axes are located.

Public interface (docs/suite.md, "The session and its guard")::

    guard.admit(frames, summed)          # a link's frames about to go out: judged once
    guard.book(exchanges, answer, at)    # ... and booked once with what the link read
    guard.check(body, address)           # before sending: raises SafetyStop / Interrupted
    guard.check_frames(frames, summed)   # the same for raw bytes, framed as a unit would
    guard.accepted(body, response, address, view)   # after the answer (None: no answer
                                                    # seen), with the view it left
"""

from __future__ import annotations

import copy
import math
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from functools import lru_cache

from conformance.link.envelope import (
    EMPTY,
    INF,
    UNKNOWN,
    ZERO,
    Envelope,
    Outcome,
    Read,
    Span,
    point,
)
from conformance.link.framing import HostFrame, Response
from conformance.link.ledger import EepromLedger
from conformance.link.signals import Interrupted, Interrupts
from conformance.protocol.bounded import decimal
from conformance.protocol.catalogue import catalogue, classes, eeprom_width
from conformance.protocol.parse import parse
from conformance.protocol.view import View, observe
from conformance.protocol.wire import is_hex_byte
from gve_fixtures.profile import Profile
from gve_fixtures.protocol import ErrorCode, St6


class SafetyStop(BaseException):
    """A frame the suite refused to send to a real unit: the case ends COULD-NOT-TEST.

    A BaseException, so that no case and no Hypothesis machine takes it for a failure
    and tries the frame again."""


class BeyondEnvelope(SafetyStop):
    """A motion frame after which an axis could leave the envelope (a machine that draws
    its vectors may draw another instead: :meth:`Guard.fits`)."""


@dataclass
class Sighting:
    """What the guard saw of the axes it could not follow: what the unit showed, where
    the axes may be, and what the run did about it."""

    seen: str
    where: str
    then: str

    def __str__(self) -> str:
        return f"{self.seen}; {self.where}: {self.then}"


class Restart(Sighting):
    """A restart the guard saw (the power-on facts read)."""


class Untracked(Sighting):
    """Counters read at rest that the frames cannot explain, and no power-on facts: what
    was read after the frames since the last read that agreed."""


#: the frames since the last read that agreed that a disagreement names (the last ones)
FRAMES_SHOWN = 12


class UnitRestarted(SafetyStop):
    """The unit restarted by itself (or its counters no longer tell where its axes are):
    the case in which it was seen ends COULD-NOT-TEST with what was seen."""


class TargetNotResponding(BaseException):
    """Several frames in a row got no answer: the run stops for this target."""


#: frames that can start an axis moving (and so ask the operator first)
MOTION = classes(motion=True)
#: frames that change what outlives the run: restart, reference run, EEPROM
DESTRUCTIVE = classes(destructive=True)
#: the longest an answer is waited for (a `W` whose run would take longer: the unit
#: refuses such a travel or rate, or the run is not one a test should wait out)
LONGEST_ANSWER_S = 600.0
_PACKET_MEMBERS = classes(packet="member")
#: frames that set the checksum mode, and so how the unit reads the frames after them
_SUMMING = classes(summing=True)
#: frames whose answer reads the position counters
_POSITION = classes(position=True)
#: what a command sets moving again, by name: "queue" or "save"
_RESUMES = {n: c.resumes for n, c in catalogue().items() if c.resumes}
#: consecutive frames without an answer after which the target is given up
SILENCE_LIMIT = 4
#: ... once they have been silent for this many of the unit's restart times (spec 2: a
#: unit that restarts answers again after about 2 s): a unit that restarted by itself is
#: not given up in virtual time, where frames time out quickly
SILENT_RESTARTS = 2


class _Depth:
    """How many blocks of one kind are open (they nest): ``with depth:`` opens one; the
    depth is true while any is open."""

    def __init__(self) -> None:
        self.open = 0

    def __bool__(self) -> bool:
        return self.open > 0

    def __enter__(self) -> None:
        self.open += 1

    def __exit__(self, *exc: object) -> None:
        self.open -= 1


@dataclass(frozen=True)
class Body:
    """A frame's body as the guard reads it: leniently (a unit that is not conforming
    may take `l` for `L` or `+5` for 5), so that no reading of it goes unjudged."""

    name: str
    params: str

    @classmethod
    @lru_cache(maxsize=4096)     # every frame is parsed several times; a Body is immutable
    def parse(cls, body: str) -> Body:
        """The frame's class (``SW6`` for a write of ST6, "" for no command of spec 10)
        and its parameters, read leniently."""
        parsed = parse(body)
        return cls(parsed.key, parsed.params)

    def fields(self, count: int) -> list[Span]:
        """The first ``count`` comma-separated integers (missing ones 0, unreadable ones
        unbounded)."""
        parts = self.params.split(",") if self.params else []
        return [_number(parts[i]) if i < len(parts) else ZERO for i in range(count)]


def _number(text: str, base: int = 10) -> Span:
    text = text.strip().lstrip("+")
    if text == "":
        return ZERO
    try:
        return point(int(text, base))
    except ValueError:
        return UNKNOWN


@dataclass(frozen=True)
class Admitted:
    """What the guard said of frames it let out: how long the last one's answer may
    take (None: at once), and whether they are the session's own frames or its `H` and
    `D` after Ctrl-C (``own``, ``urgent``), which a signal that comes before they are
    written keeps off the line or not (:meth:`Interrupts.bars`)."""

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


def outcome_of(r: Response | None) -> Outcome:
    if r is None or r.code is None:
        return Outcome.UNCLEAR
    return Outcome.ACCEPTED if r.ok else Outcome.REFUSED


class Guard:
    """One real unit's run-wide guard (see the module's docstring). It owns what the run
    knows of the unit's safety: the envelope, the EEPROM ledger, the run's Ctrl-C."""

    def __init__(self, profile: Profile, address: int, *, max_travel: int,
                 allow_destructive: bool, interrupts: Interrupts | None = None) -> None:
        self.profile = profile
        self.address = address
        self.max_travel = max_travel
        self.allow_destructive = allow_destructive
        self.interrupts = interrupts or Interrupts()
        micro = profile.microstep
        self.scale = profile.position_scale               # counter units per full step
        self.envelope = Envelope(
            len(profile.axes), self._limit(max_travel),
            tuple(micro.factors.values()) if micro else (1,),
            micro.factors[micro.reset_mode] if micro else 1)
        self.addresses = {address} | ({profile.spindle.address} if profile.spindle else set())
        #: the unit as the wire shows it (protocol/view.py), as the link that sent the
        #: last frame booked saw it: the guard reads the open packet there
        self.view = View(addresses=frozenset(self.addresses))
        self.eeprom = EepromLedger()
        self.before_motion: Callable[[], bool | None] | None = None
        self.motion_confirmed: bool | None = None
        self.silences = 0
        self.garbage = ""                         # the last bytes that were not an answer
        self.dead = False
        self._silent_from: int | None = None      # when the frames in a row went unanswered (ns)
        self.unanswered = 0                       # frames unanswered since a read agreed
        self._restarting = False                  # after J or the rig's power-on: deaf a while
        self._last = ""                           # the command booked last
        self._summing = False                     # %+ booked since a frame went unanswered
        #: the unit's restarts seen (and counters that no longer told where the axes
        #: were), for the report
        self.restarts: list[Restart] = []
        self._told = 0                            # restarts a case has been stopped for
        #: counters read at rest that the frames could not explain, with no restart's
        #: power-on counters (the report's; the case that read them judges them)
        self.untracked: list[Untracked] = []
        #: the frames booked since a position read at rest last agreed, with their answers
        self.since: list[str] = []
        #: what the unit read since then of the other power-on facts (spec 9): ST0..ST6
        #: and `@` by name, each (the value read, the frames booked before it)
        self._facts: dict[str, tuple[int, int]] = {}
        #: the frames booked before the latest one that went unanswered since then: a
        #: restart there, facts read before it are the unit's from before
        self._silent_at = 0
        self._lost_by: Restart | Untracked | None = None    # what set :attr:`lost`
        #: why no motion frame may go out (the axes are not known to be anywhere exact
        #: since a restart); "" while they are
        self.lost = ""
        self._own = _Depth()                      # inside the session's own frames
        self._emergency = _Depth()
        self._hands_on = _Depth()                 # a technician's hand step is open
        self._unmoved = _Depth()                  # reads with nothing moved since the last
        #: the envelope was re-centred where a co-simulator's axes stood (recentre)
        self.recentred = False

    def _limit(self, max_travel: int) -> float:
        """The envelope's reach either side, in counter units."""
        return max_travel * self.scale

    @property
    def packet_open(self) -> bool:
        """Whether a packet may be open (the view's): its members go unanswered."""
        return self.view.packet_open

    # -- who is sending ----------------------------------------------------------------------
    def own_frames(self) -> _Depth:
        """The session's own frames (known state, snapshot, restorations): after Ctrl-C
        these still go out, except motion."""
        return self._own

    def emergency(self) -> _Depth:
        """`H` and `D` after Ctrl-C: the frames that go out before anything else."""
        return self._emergency

    def unmoved(self) -> _Depth:
        """Position reads the session takes at rest with nothing sent that moves since the
        bookkeeping last knew where the axes are (right after `N`): a counter read
        otherwise is a counter that did not take the set, never motion."""
        return self._unmoved

    def hands_on(self) -> _Depth:
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
        if self.dead:
            raise TargetNotResponding(self._not_responding())
        self._tell_restart()

    def _tell_restart(self) -> None:
        """End the case that is running when a restart was seen (once per restart; the
        session's own frames go on: it reports the restart)."""
        if self._told < len(self.restarts) and not self._own and not self._emergency:
            self._told = len(self.restarts)
            raise UnitRestarted(str(self.restarts[-1]))

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

    def book(self, exchanges: list[tuple[str, Response | None, int, View]],
             answer: Response | None = None, at: int | None = None, *,
             heard: bool = False) -> None:
        """Book the frames of one exchange, each with its answer and the view it left
        (:meth:`accepted`), and, ``heard``: what the link read for the last one
        (:meth:`answered`, ``at`` the instant it went out): one call per exchange."""
        for body, response, address, view in exchanges:
            self.accepted(body, response, address, view)
        if heard:
            self.answered(answer, at)

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
        start = _number(command.params.split(",")[0], 16)
        if not start.exact:
            return []
        size = self.profile.eeprom.size
        return [(int(start.lo) + i) % size for i in range(width)]

    def farthest(self, body: str) -> float:
        """How far (full steps) from where the run began an axis could be once the frame
        ``body`` went out: the envelope it needs now (inf: it cannot be bounded)."""
        command = Body.parse(body)
        reach = self._reach(command) if command.name in MOTION else self.envelope.reach()
        return max(max(-_steps(s.lo, self.scale), _steps(s.hi, self.scale)) for s in reach)

    def _reach(self, command: Body) -> list[Span]:
        event = self._event(command, Outcome.UNCLEAR, None)
        return self.envelope.would_reach(event) if event else self.envelope.reach()

    def _check_motion(self, body: str, command: Body) -> None:
        e = self.envelope
        reach = self._reach(command)
        axis = e.outside(reach)
        if axis is not None:
            span = reach[axis]
            raise BeyondEnvelope(
                f"{body}: axis {self.profile.axes[axis]} could reach "
                f"{_steps(span.lo, self.scale)}..{_steps(span.hi, self.scale)} full steps "
                f"from where the run began, beyond the envelope ±{self.max_travel}")
        # G and a write of ST6 resume the queue, R the save: they move only when something waits
        waiting = {"queue": any(p != EMPTY for p in e.queue),
                   "save": e.saved is not None and e.save_moves}.get(
                       _RESUMES.get(command.name, ""), False)
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

    # -- after a frame ------------------------------------------------------------------------
    def accepted(self, body: str, response: Response | None, address: int | None = None,
                 view: View | None = None) -> None:
        """Book the frame ``body`` with its answer (None when none was seen); ``view``:
        the unit as the wire shows it after the exchange (a link's, which observed it),
        else the guard's own view observes it."""
        address = self.address if address is None else address
        if address not in self.addresses:
            return
        self.view = (observe(self.view, body, response, address) if view is None
                     else view)
        command = Body.parse(body)
        outcome = outcome_of(response)
        if command.name in _PACKET_MEMBERS and self.view.role == "member":
            if command.name == "C":
                # a member (unanswered) may be committed as it arrives, or only at *E,
                # or never (all-or-nothing is our reading [D]): maybe, from now on;
                # answered, the unit did not take it as one
                self.envelope.vector(command.fields(self.envelope.axes), outcome,
                                     stand_alone=False)
            self._follow(body, response)
            return
        event = self._event(command, outcome, None if response is None else response.code)
        if event is not None:
            event(self.envelope)
        self._follow(body, response)
        self._last = command.name
        self._summing = self._summing or command.name == "%+"
        if command.name == "J" and outcome is not Outcome.REFUSED:
            self._restarting = True          # its silence is the suite's own doing
        self._learn(command, response, outcome)

    def _follow(self, body: str, response: Response | None) -> None:
        """Keep ``body`` with its answer among the frames since the last read that agreed
        (only the last :data:`FRAMES_SHOWN` and how many came before them are shown)."""
        answer = "no answer" if response is None else response.text.removesuffix("\\r")
        self.since.append(f"{body} → {answer}")

    def _frames_since(self) -> str:
        """The frames since the last read that agreed, as a disagreement names them."""
        shown = self.since[-FRAMES_SHOWN:]
        earlier = len(self.since) - len(shown)
        return (f"{earlier} frame(s), then " if earlier else "") + "; ".join(shown)

    # -- frames told ahead ------------------------------------------------------------------
    def ahead(self) -> Guard:
        """A copy of this guard on which frames told ahead of their sending (a
        co-simulator's `batch`) are judged one after the other, each booked with
        :meth:`book_any` once judged: a frame the copy lets through, this guard lets
        through when it comes to be sent, whatever the unit answered the ones before it.
        The copy asks nobody (motion not confirmed yet is refused on it) and changes
        nothing here."""
        trial = copy.copy(self)
        trial.envelope, trial.eeprom = _copied(self.envelope), _copied(self.eeprom)
        trial.since, trial.restarts, trial.untracked = \
            list(self.since), list(self.restarts), list(self.untracked)
        if self.motion_confirmed is None and self.before_motion is not None:
            trial.before_motion = lambda: False
        return trial

    def book_any(self, body: str, address: int | None = None) -> None:
        """Book the frame ``body`` as though it got any answer at all: what it may have
        done counted whichever way reaches farther (an unclear outcome), and a `C` while
        a packet may be open as a vector that may or may not have been taken (a member
        counts so from when it is sent). What only an answer tells (the unit at rest,
        where the axes are) is not learnt."""
        address = self.address if address is None else address
        if address not in self.addresses:
            return
        self.accepted(body, None, address)

    def restarted(self) -> None:
        """The unit restarted by other means than `J` (a test rig's power cycle): booked
        as a `J` it accepted (counters zeroed, queue and packet gone, the axes stay)."""
        self.envelope.discard(Outcome.ACCEPTED, restart=True)
        self.view = self.view.restarted()
        self._restarting = True

    def recentre(self) -> None:
        """A co-simulator just powered on (counters 0): its axes are taken as standing
        where the run began, so the envelope bounds the next frames from there. Only for
        a unit that moves nothing physical (docs/decisions.md); :attr:`recentred` says the
        run's origin moved."""
        axes = range(self.envelope.axes)
        self.locate(dict.fromkeys(axes, 0), dict.fromkeys(axes, 0))
        self.recentred = True

    def locate(self, physical: dict[int, int], counters: dict[int, int]) -> None:
        """The axes stand still at ``physical`` (counter units from where the run began,
        as a test rig's eyes see them) while the counters read ``counters``: motion may
        go out again."""
        self.envelope.locate(physical, counters)
        if self.lost and self._lost_by is not None:
            self._lost_by.then = (f"the test rig then located them at "
                                  f"{self.whereabouts()}, and motion went on from there")
        self.lost, self.unanswered, self._lost_by = "", 0, None
        self.since, self._facts, self._silent_at = [], {}, 0

    def _event(self, command: Body, outcome: Outcome,
               code: int | None) -> Callable[[Envelope], None] | None:
        """What ``command`` does to the envelope with ``outcome`` (None: nothing);
        ``code`` is the answer's code when there was one."""
        simple = _EVENTS.get(command.name)
        if simple is not None:
            return lambda e: simple(e, outcome)
        build = {"L": self._vector, "C": self._vector, "*E": self._vector,
                 "N": self._counters, "NX": self._counters, "NY": self._counters,
                 "NZ": self._counters, "NA": self._counters, "W": self._reference,
                 "M": self._mode}.get(command.name)
        return None if build is None else build(command, outcome, code)

    def _vector(self, command: Body, outcome: Outcome,
                code: int | None) -> Callable[[Envelope], None]:
        """`L` and `C`; a `C` member of an open packet counts as maybe taken from when it
        is sent (a unit may commit members as they arrive), so `*E` adds nothing to
        them, whatever its answer."""
        steps = command.fields(self.envelope.axes)
        if command.name == "*E":
            return lambda e: None
        if command.name == "C" and self.packet_open:
            return lambda e: e.vector(steps, Outcome.UNCLEAR, stand_alone=False)
        return lambda e: e.vector(steps, outcome, stand_alone=command.name == "L")

    def _mode(self, command: Body, outcome: Outcome,
              code: int | None) -> Callable[[Envelope], None] | None:
        """GVE54 `M`: the micro-step mode of later vectors (currents change nothing)."""
        micro = self.profile.microstep
        factor = micro.factors.get(command.params.strip()) if micro else None
        return None if factor is None else (lambda e: e.mode(factor, outcome))

    def _counters(self, command: Body, outcome: Outcome,
                  code: int | None) -> Callable[[Envelope], None]:
        """`N` zeroes every counter, `N<axis> n` sets one; a value the guard cannot read
        leaves that counter unknown."""
        names = self.profile.axes
        if command.name == "N":
            known = not command.params              # N with junk: a bad parameter
            values = {i: 0 if known else None for i in range(len(names))}
        elif command.name[1] in names:
            value = _number(command.params)
            values = {names.index(command.name[1]): int(value.lo) if value.exact else None}
        else:
            values = {}
        return lambda e: e.counters(values, outcome)

    def _reference(self, command: Body, outcome: Outcome,
                   code: int | None) -> Callable[[Envelope], None]:
        """`W<axis>,n2,n3,n4,n5`: to the switch within n2, back within n4 (spec 10 W).
        Answered 5 (no switch, or still active) the axis has moved all the same."""
        names = self.profile.axes
        axis = command.params[:1]
        n2, _, n4, _ = Body("W", command.params[1:].lstrip(",")).fields(4)
        if code == ErrorCode.RANGE:
            outcome = Outcome.ACCEPTED
        zeroed = code == ErrorCode.OK
        if axis not in names or not (n2.exact and n4.exact):
            every = range(len(names))
            return lambda e: [e.reference(i, UNKNOWN, outcome, zeroed=True) for i in every]
        to, back = int(n2.lo), abs(int(n4.lo))
        travel = Span(min(0, to) - (back if to > 0 else 0), max(0, to) + (back if to < 0 else 0))
        i = names.index(axis)
        return lambda e: e.reference(i, travel, outcome, zeroed=zeroed)

    def _learn(self, command: Body, r: Response | None, outcome: Outcome) -> None:
        """What an answer tells beyond the command itself: the unit shows it rests, a
        position is read (the open packet is the view's)."""
        name = command.name
        if outcome is not Outcome.ACCEPTED or r is None:
            return
        self._fact(command, r)
        if (name == "SR" and _number(command.params) == point(6)) or name == "F":
            st6 = r.values[0] if r.values else ""
            if is_hex_byte(st6) and not int(st6, 16) & (St6.RUN | St6.STOP):
                self.envelope.ended()
        elif name in _POSITION:
            axes = 2 if name == "P" else min(3, self.envelope.axes)
            read = [decimal(v, signed=True) for v in r.values[:axes]]
            if len(read) == axes and None not in read:
                self._read(name, dict(enumerate(read)),
                           summed=bool(r.checksum_ok))

    def _read(self, name: str, counters: dict[int, int], *, summed: bool = False) -> None:
        """A position read (``summed``: its answer carried a right checksum): when it tells the
        counters no longer count from where the frames say, the axes are located on their
        trail and the event is kept for the report; motion stops unless they cannot have
        moved since. A restart (the power-on counters after frames were lost, or with
        the other power-on facts of spec 9 read since) ends the case; other counters, the
        power-on counters alone among them, go back to the case, which judges them."""
        e = self.envelope
        if self._unmoved:                  # nothing moved since: a counter, not the axes
            e.anchor(counters)
            self.unanswered = 0
            self.since, self._facts, self._silent_at = [], {}, 0
            return
        expected = e.expected(sorted(counters))
        read = e.observe(counters, silence=self.unanswered > 0)
        if read in (Read.AGREES, Read.UNHELD):
            self.unanswered = 0
            self.since, self._facts, self._silent_at = [], {}, 0
        if read not in (Read.RESTARTED, Read.CONTRADICTS):
            return
        shown = ",".join(str(v) for v in counters.values())
        frames = ",".join(_counts(s) for s in expected)
        silent = (f" after {self.unanswered} frame(s) went unanswered" if self.unanswered
                  else "")
        led, unanswered = self._frames_since(), self.unanswered
        followed = self._unfollowed()
        against, unread = self._power_on_facts(summed)
        self.unanswered = 0
        self.since, self._facts, self._silent_at = [], {}, 0
        if read is Read.RESTARTED and (against or (unread and not unanswered)):
            # the power-on counters, but not the other power-on facts (spec 9): no restart
            # is said; the unit may have moved by a wrong amount back to where it began
            why = ("; ".join(against) if against else
                   f"{', '.join(unread)} not read since, no frame lost")
            record = Untracked(
                f"the position counters disagree with the frames: {name} read {shown} at "
                f"rest (the power-on counters, spec 9, but no restart: {why}) where the "
                f"frames since the last read that agreed put them at {frames}"
                f"{followed} (frames: {led or 'none'})", "", "")
            self.untracked.append(record)
            self._locate_on_trail(record)
            return
        if read is Read.CONTRADICTS and not unanswered:
            # no power-on counters and no frame lost: no restart is said (spec 2, 9); the
            # unit moved otherwise than the frames say, or its axes were moved by other
            # means
            record = Untracked(
                f"the position counters disagree with the frames: {name} read {shown} at "
                f"rest where the frames since the last read that agreed put them at "
                f"{frames}{followed} (frames: {led or 'none'})", "", "")
            self.untracked.append(record)
            self._locate_on_trail(record)
            return
        if read is Read.CONTRADICTS:
            what = (f"the position counters no longer tell where the axes are: {name} read "
                    f"{shown} at rest where the frames put them at {frames}{silent} (a unit "
                    "that restarts by itself loses the frames sent meanwhile, spec 2, and "
                    f"may have moved on since; frames: {led})")
        elif any(not s.exact or s.lo != 0 for s in expected):
            what = (f"the unit restarted by itself: {name} read {shown} at rest, the "
                    f"power-on counters (spec 9), where the frames put them at "
                    f"{frames}{silent}")
        else:
            what = (f"the unit restarted by itself, as far as the suite can tell: "
                    f"{unanswered} frame(s) went unanswered, then {name} "
                    f"read {shown}, the power-on counters (spec 9), after the axes had "
                    "moved")
        self.restarts.append(Restart(what, "", ""))
        self._locate_on_trail(self.restarts[-1])

    def _unfollowed(self) -> str:
        """The first motion frame since the last read that agreed: the one whose run the
        guard could not follow (the counters tell another)."""
        for entry in self.since:
            body = entry.split(" → ")[0]
            if Body.parse(body).name in MOTION:
                return f"; the first frame it could not follow: {entry}"
        return ""

    def _power_on_facts(self, summed: bool) -> tuple[list[str], list[str]]:
        """The other power-on facts of spec 9 as the unit read them since the last read
        that agreed: those it contradicted (a status word not 00, an index that did not
        count from 0 since, the read's answer summed: ``summed``, the checksum mode on),
        and those it did not read."""
        # after frames went unanswered, only what was read after the last of them
        since = self._silent_at if self.unanswered else 0
        facts = {k: v for k, v in self._facts.items() if v[1] >= since}
        against, unread = [], []
        for n in range(7):
            value = facts.get(f"ST{n}", (None, 0))[0]
            # ST6: the GVE114's hand wheel enabled in EEPROM holds RUN after power-on
            allowed = {0, St6.RUN} if n == 6 and self.profile.mpg is not None else {0}
            if value is None:
                unread.append(f"ST{n}")
            elif value not in allowed:
                against.append(f"ST{n} read {value:02X}")
        index = facts.get("@")
        if index is None:
            unread.append("the index (@)")
        elif index[0] > index[1] - since:
            against.append(f"@ read {index[0]} after {index[1] - since} frame(s) since")
        if summed:
            against.append("the answer came summed: the checksum mode is on")
        return against, unread

    def _fact(self, command: Body, r: Response) -> None:
        """A power-on fact read (spec 9): a status word, the index."""
        if command.name == "SR":
            n = _number(command.params)
            value = r.values[0] if r.values else ""
            if n.exact and 0 <= n.lo <= 6 and is_hex_byte(value):
                self._facts[f"ST{int(n.lo)}"] = (int(value, 16), len(self.since))
        elif command.name == "@" and r.values:
            index = decimal(r.values[0])
            if index is not None:
                self._facts["@"] = (index, len(self.since))

    def _locate_on_trail(self, record: Restart | Untracked) -> None:
        """Where the axes are after a read the frames cannot explain: exact where they
        cannot have moved since they last were known (the run goes on from there), else
        somewhere on their trail, and no motion frame goes out until they are located."""
        if all(s.exact for s in self.envelope.start):
            record.where = (f"the axes stood at {self.whereabouts()} (they had not moved "
                            "since they were last known)")
            record.then = "the run went on from there"
            return
        record.where = f"the axes stopped somewhere in {self.whereabouts()}"
        record.then = "no motion frame went out after it"
        self.lost = f"{record.seen}; {record.where}, and nothing tells where exactly"
        self._lost_by = record

    def whereabouts(self) -> str:
        """Where each axis is, in full steps from where the run began: ``X 0..1500, Y 0``."""
        return ", ".join(f"{a} {self.where(i)}" for i, a in enumerate(self.profile.axes))

    def where(self, axis: int) -> str:
        """Where ``axis`` may be, in full steps from where the run began: ``0..1500``."""
        return _span(self.envelope.reach()[axis], self.scale)

    def doubt_rest(self) -> None:
        """The unit showed that something may still move although an answer said
        otherwise (a `D` answered 0 that left INTA and RUN): no position read tells where
        the axes rest until the unit shows rest again (RUN = 0, an `L` or `N` it takes)."""
        self.envelope.settled = False

    @property
    def keep_held(self) -> bool:
        """Whether a `K` the unit took (or may have) holds a save no `R` or `J` gave back."""
        return self.envelope.saved is not None

    # -- answers and silences ----------------------------------------------------------------
    def answered(self, response: Response | None, at: int | None = None) -> None:
        """Count frames in a row that got no answer (or bytes that are not one); ``at``:
        the instant the frame went out (ns on the line's clock). A frame unanswered
        outside a restart the suite caused may be a restart's (spec 2: bytes are lost
        while a unit restarts): the next position read is weighed with it
        (:meth:`_read`)."""
        if response is not None and response.code is not None:
            self.silences, self.garbage, self._silent_from = 0, "", None
            if self._last != "J":                # the J's own answer comes before its silence
                self._restarting = False
            if response.checksum_ok and not self._summing:
                # summed without a %+ since: the checksum mode outlived the silence, and a
                # unit that restarts leaves it off (spec 6, 9)
                self.unanswered = 0
            self._tell_restart()
            return
        if response is None and self.view.silent_by_rule:
            return              # a packet's members are answered by nothing (spec 7)
        self.silences += 1
        if self._silent_from is None:
            self._silent_from = at
        if not self._restarting and response is None:
            # only silence is a restart's (spec 2: bytes are lost while a unit restarts);
            # bytes that are no answer the suite could read (a `>` answered in one line
            # where it awaited two) came from a unit that was there to send them
            self.unanswered += 1
            self._silent_at = len(self.since)
            self._summing = False
        if response is not None:
            self.garbage = response.text
        if self.silences >= SILENCE_LIMIT and self._silent_long(at) and not self._emergency:
            self.dead = True
            self.check_idle()

    def _silent_long(self, at: int | None) -> bool:
        """Whether the frames unanswered in a row went out over long enough to give the
        unit up: longer than it would take to restart (spec 2), so that one that did is
        heard again (a frame sent while it was deaf, `H` above all, may wait long for an
        answer that cannot come: the instants are when the frames went out)."""
        if at is None or self._silent_from is None:
            return True
        return at - self._silent_from >= SILENT_RESTARTS * self.profile.restart_ms * 1_000_000

    def _not_responding(self) -> str:
        last = f" (the last bytes were not an answer: {self.garbage})" if self.garbage else ""
        return f"target not responding: {self.silences} frames unanswered{last}"

    @property
    def responding(self) -> bool:
        return self.silences < SILENCE_LIMIT

    # -- timing ---------------------------------------------------------------------------------
    def stop_seconds(self) -> float:
        """The longest a stop can take (`H` answers when it ends): braking at the
        smallest acceleration over the longest distance the envelope allows (both
        directions), or from the fastest rate where there is no envelope."""
        a_min = self.profile.range("A").lo * 1000.0 * self.envelope.factor.lo
        if math.isinf(self.envelope.limit):
            return self.profile.max_rate / a_min
        return math.sqrt(2 * 2 * self.envelope.limit / a_min)

    def answer_seconds(self, body: str) -> float | None:
        """How long `H` and `W` may take before they answer (None: at once)."""
        command = Body.parse(body)
        if command.name == "H":
            return 2 * self.stop_seconds()
        if command.name == "W":
            n2, n3, n4, n5 = Body("W", command.params[1:].lstrip(",")).fields(4)
            if all(x.exact for x in (n2, n3, n4, n5)) and n3.lo > 0 and n5.lo > 0:
                run = abs(n2.lo) / n3.lo + abs(n4.lo) / n5.lo + 4 * self.stop_seconds()
                return min(run, LONGEST_ANSWER_S)
            return LONGEST_ANSWER_S
        return None

    # -- the report ---------------------------------------------------------------------------
    def excursion(self) -> list[tuple[float, float]]:
        """Per axis, the farthest the axis may have gone each way, in full steps."""
        return [(_steps(s.lo, self.scale), _steps(s.hi, self.scale)) for s in self.envelope.seen]


class EmulatorGuard(Guard):
    """The embedded emulator's guard: every link is a fresh unit and nothing outlives the
    run, so no frame is refused or booked; it still stops the run for Ctrl-C and for a
    unit that stopped answering."""

    def __init__(self, profile: Profile, address: int,
                 interrupts: Interrupts | None = None) -> None:
        super().__init__(profile, address, max_travel=0, allow_destructive=True,
                         interrupts=interrupts)

    def _limit(self, max_travel: int) -> float:
        return INF

    def check(self, body: str, address: int | None = None) -> None:
        self.check_idle()

    def accepted(self, body: str, response: Response | None, address: int | None = None,
                 view: View | None = None) -> None:
        return None

    def restarted(self) -> None:
        return None

    def _silent_long(self, at: int | None) -> bool:
        return True              # a fresh unit per link: its silence is no restart's


#: commands whose effect needs nothing but the outcome
_EVENTS: dict[str, Callable[[Envelope, Outcome], None]] = {
    "D": lambda e, o: e.discard(o),                  # the queue emptied where the axes stand
    "K": lambda e, o: e.discard(o, keep=True),       # ... and saved whole
    "J": lambda e, o: e.discard(o, restart=True),    # ... counters zeroed, mode reset
    "R": lambda e, o: e.restore(o),
    "G": lambda e, o: e.unsettle(),                  # resumes what is already counted
    "SW6": lambda e, o: e.unsettle(),
}


def _copied(record: object) -> object:
    """A copy of ``record`` with containers of its own (their items, frozen spans and
    paths or numbers, shared): what the guard's bookkeeping can change in place."""
    twin = copy.copy(record)
    for name, value in vars(record).items():
        if isinstance(value, (list, dict, set)):
            setattr(twin, name, copy.copy(value))
    return twin


def _counts(span: Span) -> str:
    """Counter values as a unit reads them: ``1500``, ``0..1500``, ``?``."""
    if not span.bounded:
        return "?"
    return str(int(span.lo)) if span.exact else f"{int(span.lo)}..{int(span.hi)}"


def _span(span: Span, scale: int) -> str:
    """A span of counter units as full steps: ``300``, ``0..1500``."""
    lo, hi = _steps(span.lo, scale), _steps(span.hi, scale)
    return f"{lo:g}" if lo == hi else f"{lo:g}..{hi:g}"


def _steps(counter: float, scale: int) -> float:
    """Counter units as full steps (GVE54 counters are sixteenths)."""
    if math.isinf(counter):
        return counter
    value = counter / scale
    return int(value) if value == int(value) else round(value, 4)
