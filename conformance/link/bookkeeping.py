"""What the run knows of where a real unit's axes may be, booked from each exchange the
links observed (:meth:`Bookkeeping.book`: the frames, their answers, the views they
left): the envelope (conformance/link/envelope.py) each frame moves, the frames since
a position read last agreed, the unit's restarts and the counters no frame explains.

A unit that restarts by itself is seen in what it reads back (the envelope's
:meth:`~conformance.link.envelope.Envelope.observe`): the power-on counters (spec 9)
where the frames put the axes elsewhere, after frames went unanswered (spec 2: bytes are
lost while a unit restarts; the liveness counts them, conformance/link/liveness.py) or
with the other power-on facts read since (ST0..ST6 00, the index counting from 0, the
checksum mode off: spec 9); counters 0 alone are no restart (a unit that moved by a
wrong amount may read them). The case in which it is seen ends
(:class:`~conformance.link.stops.UnitRestarted`), the restart is kept in
:attr:`Bookkeeping.restarts` for the report, and where the axes are is no longer known
unless they cannot have moved since they last were: then no motion frame goes out
(:attr:`Bookkeeping.lost`) until the session locates them again
(:meth:`Bookkeeping.locate`).

Other counters than the frames allow are no restart: the unit moved by another amount
than the frames say (a fault a case judges), or the axes were moved by other means. The
answer goes back to the case, which judges what it read; the bookkeeping keeps what it
saw with the frames that led there (:attr:`Bookkeeping.untracked`) and, as after a
restart, lets no motion frame out until the axes are located.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TypeVar

from conformance.link.body import Body, number, outcome_of
from conformance.link.envelope import UNKNOWN, Envelope, Outcome, Read, Span, point
from conformance.link.framing import Response
from conformance.link.liveness import Liveness, Observed
from conformance.link.stops import UnitRestarted
from conformance.protocol.bounded import decimal
from conformance.protocol.catalogue import classes
from conformance.protocol.view import View, observe
from conformance.protocol.wire import is_hex_byte
from gve_fixtures.profile import Profile
from gve_fixtures.protocol import ErrorCode, St6

T = TypeVar("T")

#: frames that can start an axis moving
MOTION = classes(motion=True)
_PACKET_MEMBERS = classes(packet="member")
#: frames whose answer reads the position counters
_POSITION = classes(position=True)
#: the frames since the last read that agreed that a disagreement names (the last ones)
FRAMES_SHOWN = 12


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


class Depth:
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


class Bookkeeping:
    """One real unit's bookkeeping of its axes (see the module's docstring): it owns the
    envelope, the frames since a read agreed, the restarts and untracked counters seen,
    and the view of the unit the last frame booked left."""

    def __init__(self, profile: Profile, address: int, envelope: Envelope,
                 liveness: Liveness, addresses: frozenset[int]) -> None:
        self.profile = profile
        self.address = address
        self.addresses = addresses
        self.scale = profile.position_scale               # counter units per full step
        self.envelope = envelope
        self.liveness = liveness
        #: the unit as the wire shows it (protocol/view.py), as the link that sent the
        #: last frame booked saw it: the open packet is read there
        self.view = View(addresses=addresses)
        #: the unit's restarts seen (and counters that no longer told where the axes
        #: were), for the report
        self.restarts: list[Restart] = []
        self._told = 0                            # restarts a case has been stopped for
        #: counters read at rest that the frames could not explain, with no restart's
        #: power-on counters (the report's; the case that read them judges them)
        self.untracked: list[Untracked] = []
        #: the frames booked since a position read at rest last agreed, with their answers
        #: (None: none seen), put in words only where a disagreement names them
        self.since: list[tuple[str, Response | None]] = []
        #: what the unit read since then of the other power-on facts (spec 9): ST0..ST6
        #: and `@` by name, each (the value read, the frames booked before it)
        self._facts: dict[str, tuple[int, int]] = {}
        #: the frames booked before the latest one that went unanswered since then: a
        #: restart there, facts read before it are the unit's from before
        self._silent_at = 0
        self._lost = liveness.lost                # the liveness's frames lost, as last read
        self._lost_by: Restart | Untracked | None = None    # what set :attr:`lost`
        #: why no motion frame may go out (the axes are not known to be anywhere exact
        #: since a restart); "" while they are
        self.lost = ""
        #: position reads at rest with nothing moved since the last (Guard.unmoved)
        self.unmoved = Depth()
        #: the envelope was re-centred where a co-simulator's axes stood (recentre)
        self.recentred = False

    @property
    def packet_open(self) -> bool:
        """Whether a packet may be open (the view's): its members go unanswered."""
        return self.view.packet_open

    def book(self, exchange: Observed) -> None:
        """Book the frames of one exchange, each with its answer and the view it left
        (:meth:`accepted`); once the last one's answer was read (``heard``), a restart
        seen ends the case (:meth:`tell_restart`)."""
        for f in exchange.frames:
            self.accepted(f.body, f.answer, f.address, f.view)
        if exchange.heard and exchange.answer is not None and exchange.answer.code is not None:
            self.tell_restart(own=exchange.own, urgent=exchange.urgent)

    def _mark_silence(self) -> None:
        """Frames the liveness counted lost since the last look went unanswered after
        the frames booked so far: facts read before them are the unit's from before a
        restart there."""
        if self.liveness.lost != self._lost:
            self._lost, self._silent_at = self.liveness.lost, len(self.since)

    def copy(self, liveness: Liveness) -> Bookkeeping:
        """A copy whose envelope, records and lists are its own (frames told ahead are
        booked on it, Guard.ahead), counting silences in ``liveness``."""
        trial = shallow(self)
        trial.envelope = _copied(self.envelope)
        trial.liveness = liveness
        trial.since, trial.restarts, trial.untracked = \
            list(self.since), list(self.restarts), list(self.untracked)
        return trial

    def tell_restart(self, *, own: bool = False, urgent: bool = False) -> None:
        """End the case that is running when a restart was seen (once per restart; the
        session's own frames, ``own``, and its `H` and `D` after Ctrl-C, ``urgent``, go
        on: it reports the restart)."""
        if self._told < len(self.restarts) and not own and not urgent:
            self._told = len(self.restarts)
            raise UnitRestarted(str(self.restarts[-1]))

    def accepted(self, body: str, response: Response | None, address: int | None = None,
                 view: View | None = None) -> None:
        """Book the frame ``body`` with its answer (None when none was seen); ``view``:
        the unit as the wire shows it after the exchange (a link's, which observed it),
        else the guard's own view observes it."""
        address = self.address if address is None else address
        if address not in self.addresses:
            return
        self._mark_silence()
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
        event = self.event(command, outcome, None if response is None else response.code)
        if event is not None:
            event(self.envelope)
        self._follow(body, response)
        self._learn(command, response, outcome)

    def _follow(self, body: str, response: Response | None) -> None:
        """Keep ``body`` with its answer among the frames since the last read that agreed
        (only the last :data:`FRAMES_SHOWN` and how many came before them are shown)."""
        self.since.append((body, response))

    def _frames_since(self) -> str:
        """The frames since the last read that agreed, as a disagreement names them."""
        shown = [_followed(*entry) for entry in self.since[-FRAMES_SHOWN:]]
        earlier = len(self.since) - len(shown)
        return (f"{earlier} frame(s), then " if earlier else "") + "; ".join(shown)

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
        self.liveness.restarting()

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
        self.lost, self._lost_by = "", None
        self.liveness.agreed()
        self.since, self._facts, self._silent_at = [], {}, 0

    def event(self, command: Body, outcome: Outcome,
               code: int | None) -> Callable[[Envelope], None] | None:
        """What ``command`` does to the envelope with ``outcome`` (None: nothing);
        ``code`` is the answer's code when there was one."""
        simple = _EVENTS.get(command.name)
        if simple is not None:
            return lambda e: simple(e, outcome)
        build = _BUILT.get(command.name)
        return None if build is None else build(self, command, outcome, code)

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
            value = number(command.params)
            values = {names.index(command.name[1]): int(value.lo) if value.exact else None}
        else:
            values = {}
        every = command.name == "N"
        return lambda e: e.counters(values, outcome, every_axis=every)

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
        if (name == "SR" and number(command.params) == point(6)) or name == "F":
            st6 = r.values[0] if r.values else ""
            if (is_hex_byte(st6) and not int(st6, 16) & (St6.RUN | St6.STOP)
                    and not self.envelope.st6_written):
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
        if self.unmoved:                   # nothing moved since: a counter, not the axes
            e.anchor(counters)
            self.liveness.agreed()
            self.since, self._facts, self._silent_at = [], {}, 0
            return
        expected = e.expected(sorted(counters))
        unanswered = self.liveness.unanswered
        read = e.observe(counters, silence=unanswered > 0)
        if read in (Read.AGREES, Read.UNHELD):
            self.liveness.agreed()
            self.since, self._facts, self._silent_at = [], {}, 0
        if read not in (Read.RESTARTED, Read.CONTRADICTS):
            return
        shown = ",".join(str(v) for v in counters.values())
        frames = ",".join(counts(s) for s in expected)
        silent = f" after {unanswered} frame(s) went unanswered" if unanswered else ""
        led = self._frames_since()
        followed = self._unfollowed()
        against, unread = self._power_on_facts(summed)
        self.liveness.agreed()
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
        for body, response in self.since:
            if Body.parse(body).name in MOTION:
                return f"; the first frame it could not follow: {_followed(body, response)}"
        return ""

    def _power_on_facts(self, summed: bool) -> tuple[list[str], list[str]]:
        """The other power-on facts of spec 9 as the unit read them since the last read
        that agreed: those it contradicted (a status word not 00, an index that did not
        count from 0 since, the read's answer summed: ``summed``, the checksum mode on),
        and those it did not read."""
        # after frames went unanswered, only what was read after the last of them
        since = self._silent_at if self.liveness.unanswered else 0
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
            n = number(command.params)
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
        return span_steps(self.envelope.reach()[axis], self.scale)

    def doubt_rest(self) -> None:
        """The unit showed that something may still move although an answer said
        otherwise (a `D` answered 0 that left INTA and RUN): no position read tells where
        the axes rest until the unit shows rest again (RUN = 0, an `L` or `N` it takes)."""
        self.envelope.settled = False

    @property
    def keep_held(self) -> bool:
        """Whether a `K` the unit took (or may have) holds a save no `R` or `J` gave back."""
        return self.envelope.saved is not None

    def excursion(self) -> list[tuple[float, float]]:
        """Per axis, the farthest the axis may have gone each way, in full steps."""
        return [(steps(s.lo, self.scale), steps(s.hi, self.scale)) for s in self.envelope.seen]


#: commands whose effect needs nothing but the outcome
_EVENTS: dict[str, Callable[[Envelope, Outcome], None]] = {
    "D": lambda e, o: e.discard(o),                  # the queue emptied where the axes stand
    "K": lambda e, o: e.discard(o, keep=True),       # ... and saved whole
    "J": lambda e, o: e.discard(o, restart=True),    # ... counters zeroed, mode reset
    "R": lambda e, o: e.restore(o),
    "G": lambda e, o: e.unsettle(),                  # resumes what is already counted
    "SW6": lambda e, o: e.write_st6(o),
}


#: commands whose effect the bookkeeping works out from the command itself
_BUILT = {"L": Bookkeeping._vector, "C": Bookkeeping._vector, "*E": Bookkeeping._vector,
          "N": Bookkeeping._counters, "NX": Bookkeeping._counters,
          "NY": Bookkeeping._counters, "NZ": Bookkeeping._counters,
          "NA": Bookkeeping._counters, "W": Bookkeeping._reference, "M": Bookkeeping._mode}


def _followed(body: str, response: Response | None) -> str:
    """A frame booked with its answer, as a disagreement names it: ``L100,0,0 → 0``."""
    answer = "no answer" if response is None else response.text.removesuffix("\\r")
    return f"{body} → {answer}"


def shallow(record: T) -> T:
    """What ``copy.copy`` makes of a plain object (its attributes shared), at a fraction
    of the cost: the guard copies itself for every batch of frames told ahead."""
    twin = object.__new__(type(record))
    twin.__dict__.update(record.__dict__)
    return twin


def _copied(record: T) -> T:
    """A copy of ``record`` with containers of its own (their items, frozen spans and
    paths or numbers, shared): what the bookkeeping can change in place."""
    twin = object.__new__(type(record))
    twin.__dict__.update({name: value.copy() if isinstance(value, (list, dict, set))
                          else value for name, value in vars(record).items()})
    return twin


def counts(span: Span) -> str:
    """Counter values as a unit reads them: ``1500``, ``0..1500``, ``?``."""
    if not span.bounded:
        return "?"
    return str(int(span.lo)) if span.exact else f"{int(span.lo)}..{int(span.hi)}"


def span_steps(span: Span, scale: int) -> str:
    """A span of counter units as full steps: ``300``, ``0..1500``."""
    lo, hi = steps(span.lo, scale), steps(span.hi, scale)
    return f"{lo:g}" if lo == hi else f"{lo:g}..{hi:g}"


def steps(counter: float, scale: int) -> float:
    """Counter units as full steps (GVE54 counters are sixteenths)."""
    if math.isinf(counter):
        return counter
    value = counter / scale
    return int(value) if value == int(value) else round(value, 4)
