"""Whether the unit is there: the frames in a row that got no answer, told once per
exchange from what the link read and the view it left (protocol/view.py).

After :data:`SILENCE_LIMIT` frames in a row got no answer (or bytes that are not one),
and once they went out over longer than the unit takes to restart (spec 2: a unit that
restarts answers again after about 2 s), the run gives the target up
(:class:`TargetNotResponding`). Frames the manuals answer with nothing are no silence: a
packet's start and its members (spec 7), as the view of the link that sent them shows.
An answer is any bytes whose last line is a response (spec 4), however many lines the
case awaited: `>` answers a single line where it has no history or refuses (spec 6, 8).

It also counts, for the guard's bookkeeping, the frames lost since a position read last
agreed (:attr:`Liveness.unanswered`): a unit that restarts by itself loses the bytes
sent meanwhile (spec 2), so the next position read is weighed with them. Silence the
suite caused (a `J` it sent, a rig's power cycle) is not counted there, nor bytes that
are no answer the suite could read: a unit was there to send them.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

from conformance.protocol.catalogue import classes
from conformance.protocol.parse import parse
from conformance.protocol.view import View
from conformance.protocol.wire import CR, Response, parse_response

#: frames a packet's member may be (answered with nothing there, spec 7)
_MEMBERS = classes(packet="member")
#: consecutive frames without an answer after which the target is given up
SILENCE_LIMIT = 4
#: ... once they have been silent for this many of the unit's restart times (spec 2: a
#: unit that restarts answers again after about 2 s): a unit that restarted by itself is
#: not given up in virtual time, where frames time out quickly
SILENT_RESTARTS = 2


class TargetNotResponding(BaseException):
    """Several frames in a row got no answer: the run stops for this target."""


@dataclass(frozen=True)
class Booked:
    """One frame of an exchange as the link observed it: its body, the answer it got
    (None: none read), the address it went to, the view it left."""

    body: str
    answer: Response | None
    address: int
    view: View


@dataclass(frozen=True)
class Observed:
    """What one exchange left, told once to those who follow the unit: its frames, the
    view of the unit the link holds after it, what was read for the last one (``answer``;
    only when ``heard``: an answer was awaited and read for, else one may still come),
    the instant the frames went out (ns on the line's clock), and whether the guard let
    them out as the session's `H` and `D` after Ctrl-C (``urgent``) or as its own frames
    (``own``)."""

    frames: tuple[Booked, ...]
    view: View | None = None
    answer: Response | None = None
    at: int | None = None
    heard: bool = False
    own: bool = False
    urgent: bool = False


class Follower(Protocol):
    """What follows the unit from the exchanges a link tells it (Guard.followers)."""

    def book(self, exchange: Observed) -> None: ...


def tell_followers(exchange: Observed, bookkeeping: Follower, liveness: Liveness) -> None:
    """Tell one exchange to those who follow the unit, once each: the bookkeeping books
    its frames (and ends the case once a restart was seen: UnitRestarted), then the
    liveness counts its answer (TargetNotResponding once the unit is given up)."""
    try:
        bookkeeping.book(exchange)
    finally:
        liveness.heard(exchange)


def answer_in(response: Response | None, summed: bool) -> Response | None:
    """The answer ``response`` holds (None: bytes that are none): the response itself,
    or its last line when the lines awaited did not all come (`>` with no history
    answers `0` alone, spec 8)."""
    if response is None or response.code is not None or not response.lines:
        return None if response is None or response.code is None else response
    last = parse_response(response.lines[-1] + CR, summed=summed)
    return last if last.code is not None else None


class Liveness:
    """The run's count of frames unanswered (see the module's docstring). ``restart_ms``:
    how long the unit takes to restart (None: a fresh unit per link, whose silence is
    never a restart's)."""

    def __init__(self, restart_ms: float | None, addresses: frozenset[int]) -> None:
        self.restart_ms = restart_ms
        self.addresses = addresses
        self.silences = 0
        self.garbage = ""                         # the last bytes that were not an answer
        self.dead = False
        self._silent_from: int | None = None      # when the frames in a row went unanswered (ns)
        #: frames lost since a position read last agreed (the bookkeeping's :meth:`agreed`)
        self.unanswered = 0
        #: how many frames were ever counted lost: the bookkeeping marks where each falls
        self.lost = 0
        self._restarting = False                  # after J or the rig's power-on: deaf a while
        self._last = ""                           # the command heard of last
        self._summing = False                     # %+ sent since a frame went unanswered

    @property
    def responding(self) -> bool:
        return self.silences < SILENCE_LIMIT

    def check(self) -> None:
        """Raise :class:`TargetNotResponding` once the target was given up."""
        if self.dead:
            raise TargetNotResponding(self._not_responding())

    def restarting(self) -> None:
        """The suite restarted the unit otherwise than by `J` (a rig's power cycle): its
        silence for a while is the suite's own doing."""
        self._restarting = True

    def agreed(self) -> None:
        """A position read agreed with the frames (or the axes were located): the frames
        lost before it are weighed no more."""
        self.unanswered = 0

    def heard(self, exchange: Observed) -> None:
        """Count what one exchange showed: its frames, and (``heard``) the answer read
        for the last one; raises :class:`TargetNotResponding` when the target is given up
        (not for the session's `H` and `D` after Ctrl-C)."""
        self._sent(exchange.frames)
        if not exchange.heard:
            return
        view = exchange.view
        answer = answer_in(exchange.answer, bool(view and view.checksums))
        if answer is not None:
            self._answered(answer)
            return
        if exchange.answer is None and view is not None and view.silent_by_rule:
            return              # a packet's start and members are answered by nothing (spec 7)
        self._unanswered(exchange.answer, exchange.at)
        if not self.responding and self._silent_long(exchange.at) and not exchange.urgent:
            self.dead = True
            self.check()

    def _sent(self, frames: Sequence[Booked]) -> None:
        """What the frames sent tell of the silence to come: a `J` the unit took (or may
        have) makes it deaf a while; a `%+` sets the mode a restart would clear."""
        for f in frames:
            name = parse(f.body).key
            if f.address not in self.addresses or (
                    f.view.role == "member" and name in _MEMBERS):
                continue
            self._last = name
            self._summing = self._summing or name == "%+"
            refused = f.answer is not None and f.answer.code is not None and not f.answer.ok
            if name == "J" and not refused:
                self._restarting = True          # its silence is the suite's own doing

    def _answered(self, response: Response) -> None:
        self.silences, self.garbage, self._silent_from = 0, "", None
        if self._last != "J":                    # the J's own answer comes before its silence
            self._restarting = False
        if response.checksum_ok and not self._summing:
            # summed without a %+ since: the checksum mode outlived the silence, and a
            # unit that restarts leaves it off (spec 6, 9)
            self.unanswered = 0

    def _unanswered(self, response: Response | None, at: int | None) -> None:
        self.silences += 1
        if self._silent_from is None:
            self._silent_from = at
        if not self._restarting and response is None:
            # only silence is a restart's (spec 2: bytes are lost while a unit restarts);
            # bytes that are no answer the suite could read came from a unit that was
            # there to send them
            self.unanswered += 1
            self.lost += 1
            self._summing = False
        if response is not None:
            self.garbage = response.text

    def _silent_long(self, at: int | None) -> bool:
        """Whether the frames unanswered in a row went out over long enough to give the
        unit up: longer than it would take to restart (spec 2), so that one that did is
        heard again (a frame sent while it was deaf, `H` above all, may wait long for an
        answer that cannot come: the instants are when the frames went out)."""
        if self.restart_ms is None or at is None or self._silent_from is None:
            return True
        return at - self._silent_from >= SILENT_RESTARTS * self.restart_ms * 1_000_000

    def _not_responding(self) -> str:
        last = f" (the last bytes were not an answer: {self.garbage})" if self.garbage else ""
        return f"target not responding: {self.silences} frames unanswered{last}"
