"""A link's time: its clock (the virtual line's in virtual time, the monotonic clock in
real time), how long it waits for an answer, and where its time goes (its session's time
account, conformance/link/account.py).

An exchange's bytes at the baud rate are booked as line time and the rest as what its
caller waited for (the unit's answer, or the motion a command answers at the end of); a
pause injected into a frame is booked apart; a timeout and a quiet line are the suite's
own waits.
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Iterator

from conformance.link.account import Spent, TimeAccount
from gve_fixtures.protocol import SECOND

#: processing margin on top of the bytes' own transmission time
MARGIN = 0.25
#: real time: how long after its timeout an answer is still taken as its frame's, noted
#: as late (a loaded USB adapter's line); later than that it is a hang's
LATE = 1.0
#: real time: at the end of a case, the longest it listens for bytes still on their way
#: (a line whose round trip was measured is listened to for that long, :meth:`end_quiet`)
END_QUIET = 0.05


class LineTime:
    """One link's clock and time account. ``line``: the virtual line whose clock it
    reads (None: real time)."""

    def __init__(self, line, baud: int) -> None:
        self.line = line
        self.baud = baud
        self.virtual = line is not None
        #: real time: the line's round trip as the session measured it at its start
        #: (``SessionReport.line``; empty when it was not), for the timing bands
        self.round_trip: dict[str, float] = {}
        #: where the link's time went (its session's account, shared by its links)
        self.account = TimeAccount()
        #: the exchange whose bytes are going out: the clock when its first byte was
        #: written, its bytes, the time paused in it (booked apart); what follows its
        #: answer, or its absence, is booked with it
        self._exchange: list[int] | None = None
        #: what the wait for the next answer is booked under (the unit's answer, or
        #: the motion `H` and `W` answer at the end of)
        self.answered_as = Spent.ANSWERS
        self.origin = self.clock()

    def clock(self) -> int:
        if self.line is not None:
            return self.line.now
        return time.monotonic_ns()

    @property
    def now(self) -> int:
        """Nanoseconds since the link opened."""
        return self.clock() - self.origin

    def keep_account(self, account: TimeAccount) -> None:
        """Book this link's time in ``account`` (its session's); in virtual time the
        account's wall time follows this link's clock from now on."""
        self.account = account
        if self.virtual:
            account.follow(lambda: self.now / SECOND)

    @contextlib.contextmanager
    def spending(self, spent: Spent) -> Iterator[None]:
        """Book the time the block takes under ``spent`` (e.g. a technician's step)."""
        began = self.clock()
        try:
            yield
        finally:
            self.account.book(spent, (self.clock() - began) / SECOND)

    def wrote(self, n: int) -> None:
        """``n`` bytes of the exchange under way went out (its first begin it)."""
        if self._exchange is None:
            self._exchange = [self.clock(), 0, 0]
        self._exchange[1] += n

    def paused(self, ns: int) -> None:
        """An injected pause of ``ns`` inside the exchange under way (booked apart)."""
        if self._exchange is not None:
            self._exchange[2] += ns

    def book_exchange(self, received: int, rest: Spent, began: int) -> None:
        """Book the exchange under way (else what was read since ``began``): its bytes
        and the ``received`` ones at the baud rate as line time, the rest under ``rest``."""
        if self._exchange is not None:
            began, sent, paused = self._exchange
        else:
            sent = paused = 0
        self._exchange = None
        seconds = (self.clock() - began - paused) / SECOND
        line = min(seconds, self.byte_seconds(sent + received))
        self.account.book(Spent.LINE, line)
        self.account.book(rest, seconds - line)

    def close_exchange(self) -> None:
        """Frames sent that nothing will read an answer to: their bytes are booked now."""
        if self._exchange is not None:
            self.book_exchange(0, Spent.WAITS, 0)

    def byte_seconds(self, n: int) -> float:
        return n * 10 / self.baud

    def timeout(self, slow: float | None, size: int) -> float:
        """How long the answer to a frame of ``size`` bytes may take: the frame's and an
        answer's bytes, a margin, ``slow`` (what the command itself takes when it answers
        at its end), and what the line adds (:meth:`line_seconds`)."""
        return MARGIN + self.byte_seconds(size + 64) + (slow or 0.0) + self.line_seconds()

    def late(self) -> float:
        """How long after the timeout :meth:`timeout` gives an answer is still its frame's,
        noted as late (:data:`LATE`; nothing in virtual time, where no line delays it)."""
        return 0.0 if self.virtual else LATE

    def quiet(self) -> float:
        """Real time: how long the line must have been silent since a frame's answer was
        due before the next frame goes, once that frame timed out: the late grace
        (:data:`LATE`) and the time any answer is given beyond its frame's bytes (the
        margin, an answer's bytes at the baud rate, the line's delay: :meth:`timeout`), so
        that an answer the unit began within the grace has come whole by then; a later one
        is a hang's whichever frame it lands on (docs/decisions.md)."""
        return LATE + self.timeout(None, 0)

    def line_seconds(self) -> float:
        """Real time: twice the slowest round trip the session measured (a USB adapter
        holds an answer's bytes up to its latency timer, and may hold its last piece
        that long again); nothing in virtual time or when the line was not measured."""
        return 0.0 if self.virtual else 2 * self.round_trip.get("max_ms", 0.0) / 1e3

    def end_quiet(self) -> float:
        """Real time: how long the end of a case listens for bytes still on their way (a
        second answer follows the first at once): the line's slowest round trip as
        measured, which holds a USB adapter's latency timer once, as the second answer's
        first byte waits at most once behind the first's last (the rest of its line is
        read whole); at most :data:`END_QUIET`, and that where nothing was measured."""
        measured = self.round_trip.get("max_ms", 0.0) / 1e3
        return min(END_QUIET, measured) if measured else END_QUIET
