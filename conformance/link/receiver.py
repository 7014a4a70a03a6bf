"""The link's receiving side (conformance/link/link.py): what the unit sends, read off
the link's port and given to whom it belongs — the frame just sent, a frame sent before
(a late answer), a watchdog ending what the suite left open, or nobody (a second answer,
a late one, unsolicited bytes: :attr:`Receiver.violations`).

The receiver owns what only this side keeps: the last frame's state and answer, the
quiet kept since a timeout, when the suite's last byte went out and whether what it
left unfinished had its watchdog waited out, the late answers and the violations. The
link owns the view, the wire log and the frames sent: the receiver reads them and hands
back the view the bytes it read changed, for the link to keep.
"""

from __future__ import annotations

import contextlib
import time
from typing import Any, Protocol

from conformance.link.account import Spent
from conformance.link.framing import CR, Response, frame, parse_response, readable
from conformance.link.line_time import MARGIN, LineTime
from conformance.link.safety import Guard
from conformance.link.strays import (
    ANSWERED,
    OPEN_PACKET,
    TIMED_OUT,
    UNASKED,
    Stray,
    judge,
)
from conformance.protocol.view import View, answered_late, late
from gve_fixtures.protocol import MAX_FRAME, SECOND
from gve_fixtures.transcript import UNIT


class OwningLink(Protocol):
    """What the receiver reads of its link (conformance/link/link.py), which owns it."""

    port: Any
    guard: Guard
    time: LineTime
    dropped: bool                # an injected fault dropped the last frame
    superseded: bool             # a later link of the case took over

    @property
    def now(self) -> int: ...
    @property
    def virtual(self) -> bool: ...
    @property
    def line(self) -> Any: ...
    def byte_seconds(self, n: int) -> float: ...
    def spending(self, spent: Spent) -> contextlib.AbstractContextManager[None]: ...
    def record(self, direction: str, data: bytes, comment: str = "") -> None: ...
    def left_open(self, view: View | None = None) -> str: ...


class Receiver:
    def __init__(self, link: OwningLink) -> None:
        self.link = link
        self.violations: list[Stray] = []
        #: real time: answers that came after their timeout, within the quiet the line
        #: keeps before the next frame, taken as their frame's (notes, not violations)
        self.late: list[str] = []
        #: real time: since when the line has been heard silent after the last frame timed
        #: out (its answer's due instant; None: not since it was due)
        self._silent_from: float | None = None
        #: real time: until when the line was read (or the suite's last bytes went out):
        #: anything the unit sent since is still in the port
        self._read_to = 0.0
        self._last: tuple[str, bytes, bytes] = (UNASKED, b"", b"")   # state, frame, answer
        self._sent_until = 0      # when the last byte the suite wrote went out (ns)
        self._waited_out = True   # what is left unfinished had its watchdog waited out

    def sent(self, wire: bytes | None) -> None:
        """The link just wrote the suite's bytes (``wire``: the last frame they complete,
        None when they complete none)."""
        self._sent_until, self._waited_out = self.link.now, False
        self._read_to = time.monotonic()
        if wire is not None:
            self._last = (UNASKED, wire, b"")

    # -- reading the line -----------------------------------------------------------------
    def listen(self, seconds: float, *, stop_early: bool, already: float = 0.0) -> bytes:
        """Real time: read for ``seconds`` (``stop_early``: until the line has been quiet
        that long, ``already`` of it before the call); Ctrl-C ends the wait."""
        port, interrupts = self.link.port, self.link.guard.interrupts
        end = time.monotonic() + max(0.0, seconds - already)
        data = bytearray()
        first = True             # what waits is read even when the quiet has passed
        while (first or time.monotonic() < end) and not interrupts.pending:
            first = False
            port.timeout = min(0.05, max(0.0, end - time.monotonic()))
            got = port.read(max(1, port.in_waiting))
            data += got
            if got and stop_early:
                end = time.monotonic() + seconds
        return self.whole_line(bytes(data))

    def whole_line(self, data: bytes) -> bytes:
        """``data`` and the rest of the line it ends inside: a unit's bytes arrive one
        after another, so a read that ends while a line is on its way has its beginning
        only; what the unit wrote in one go is judged whole, as it came, never its tail
        as a second or a late answer."""
        link = self.link
        if data and not data.endswith(CR) and not link.guard.interrupts.pending:
            link.port.timeout = (MARGIN + link.byte_seconds(MAX_FRAME)
                                 + link.time.line_seconds())
            data += link.port.read_until(CR)
        self._read_to = time.monotonic()
        return data

    def during(self, seconds: float, spent: Spent) -> bytes:
        """Let ``seconds`` pass, booked under ``spent``; what arrived meanwhile."""
        link = self.link
        link.time.close_exchange()
        with link.spending(spent):
            if link.line is not None:
                link.line.advance(seconds)
                return self.whole_line(link.port.read(link.port.in_waiting))
            return self.listen(seconds, stop_early=False)

    def waited(self, data: bytes, view: View) -> View:
        """Give ``data``, which arrived during a wait, to whom it belongs: the view after."""
        rest, view = self.answers_late(data, view)
        view = view.listened()
        if rest:
            self.link.record(UNIT, rest)
            view = self._stray(rest, "during a wait", view, judged=True)
        self._last = (UNASKED, b"", b"")
        return view

    # -- answers --------------------------------------------------------------------------
    def answer(self, timeout: float | None, lines: int, summed: bool | None, late: float,
               view: View) -> tuple[bytes, Response | None, View]:
        """The bytes of the next answer (``lines`` lines), as read (see
        :meth:`Link.read_response`), what they say and the view after."""
        link, port = self.link, self.link.port
        timeout = MARGIN if timeout is None else timeout
        raw = bytearray()
        port.timeout = timeout
        self._silent_from = None
        asked = time.monotonic()
        began = link.time.clock()
        answered_as, link.time.answered_as = link.time.answered_as, Spent.ANSWERS
        for i in range(lines):
            # an answer that began in time is read to its end before it is judged
            chunk = self.whole_line(port.read_until(CR))
            if i == 0 and not chunk:
                self._silent_from = time.monotonic()       # due, and nothing came
            if i == 0 and late and not chunk.endswith(CR) \
                    and not link.guard.interrupts.pending:
                port.timeout = late
                chunk += port.read_until(CR)
                if chunk.endswith(CR):
                    self.late.append(f"{readable(self._last[1]) or 'a frame'} answered "
                                     f"{time.monotonic() - asked:.3f} s after it was sent, "
                                     f"{timeout:.3f} s allowed")
                elif chunk:
                    self._silent_from = None
            raw += chunk
            if not chunk.endswith(CR):
                break
            port.timeout = MARGIN + link.time.line_seconds()
        data, view = self._behind_late(bytes(raw), lines, view)
        # an answer that did not come (or not whole) was waited for to the suite's deadline
        link.time.book_exchange(len(data), answered_as if data.endswith(CR) else Spent.WAITS,
                                began)
        summed = view.checksums if summed is None else summed
        real = parse_response(data, summed=summed, lines=lines) if data else None
        if data:
            link.record(UNIT, data)
            real.received_at = link.now
        answered = real is not None and real.code is not None
        # a frame an injected fault dropped cannot be answered late
        self._last = (ANSWERED if answered else UNASKED if link.dropped else TIMED_OUT,
                      self._last[1], data)
        return data, real, view

    def _behind_late(self, data: bytes, lines: int, view: View) -> tuple[bytes, View]:
        """The answer to the frame just sent, when frames sent before it with no answer
        awaited may have been answered all the same (a unit that did not take one as a
        packet's member): answers keep the order of their frames, so while another
        answer follows at once, the one before it is an earlier frame's
        (:meth:`answers_late`)."""
        link = self.link
        while (lines == 1 and data.endswith(CR) and view.answerable
               and not link.guard.interrupts.pending):
            link.port.timeout = (MARGIN + link.byte_seconds(MAX_FRAME)
                                 + link.time.line_seconds())
            behind = self.whole_line(link.port.read_until(CR))
            if not behind.endswith(CR):
                return data + behind, view
            rest, view = self.answers_late(data, view)
            if rest:
                return data + behind, view
            data = behind
        return data, view

    def answers_late(self, data: bytes, view: View) -> tuple[bytes, View]:
        """Give each whole line of ``data`` that came after its frame to the frame it
        answers: the first sent with no answer awaited that may have one (a frame the
        unit did not take as a packet's member); returns the lines nobody's and the view
        after."""
        lines = data.split(CR)
        taken = 0
        for line in lines[:-1]:
            if not view.answerable:
                break
            r = parse_response(line + CR, summed=view.checksums)
            after = late(view, r) if r is not None and r.code is not None else None
            if after is None:
                break
            owner = answered_late(view)
            assert owner is not None
            frame_text = readable(frame(owner.body, owner.address, owner.before.checksums))
            self.link.record(UNIT, line + CR, f"the answer to {frame_text}, sent before")
            view = after
            taken += len(line) + 1
        return data[taken:], view

    def rest_of_answer(self, seconds: float = MARGIN) -> bytes:
        """The lines that follow an answer at once, taken as part of it (not as a
        second answer): a unit reading a [D] point otherwise may answer a frame with
        more lines than expected (`>` after `@`, if `@` is remembered)."""
        link, port = self.link, self.link.port
        raw = bytearray()
        port.timeout = seconds
        began = link.time.clock()
        while True:
            chunk = port.read_until(CR)
            raw += chunk
            if not chunk.endswith(CR):
                break
            port.timeout = link.byte_seconds(64)
        self._read_to = time.monotonic()
        link.time.book_exchange(len(raw), Spent.WAITS, began)
        if raw:
            link.record(UNIT, bytes(raw), "the rest of the answer")
        return bytes(raw)

    # -- bytes nothing asked for ----------------------------------------------------------
    def settle(self, final: bool, view: View) -> tuple[bytes, View]:
        """What arrived although nothing was asked, and the view after (see
        :meth:`Link.settle`)."""
        link = self.link
        state = self._last[0]
        link.time.close_exchange()
        data = self._outwait(final, view)
        kept_quiet = False
        if not link.virtual:
            if state == TIMED_OUT and not link.guard.interrupts.pending:
                # the silence heard since the answer was due counts (the late grace, a
                # watchdog waited out with nothing said)
                silent = (time.monotonic() - self._silent_from
                          if self._silent_from is not None and not data else 0.0)
                with link.spending(Spent.WAITS):
                    data += self.listen(link.time.quiet(), stop_early=True, already=silent)
                kept_quiet = not link.guard.interrupts.pending
            elif final:
                # the silence since the line was last read counts (what came since waits
                # in the port, and is read first)
                silent = 0.0 if data else time.monotonic() - self._read_to
                with link.spending(Spent.WAITS):
                    data += self.listen(link.time.end_quiet(), stop_early=True,
                                        already=silent)
        self._silent_from = None
        waiting = link.port.in_waiting
        if waiting:
            data += link.port.read(waiting)
        data = self.whole_line(data)
        rest, view = self.answers_late(data, view)
        if not rest:
            if kept_quiet or data:       # the timed-out frame's answer can come no more
                self._last = (UNASKED, b"", b"")
            return data, view
        link.record(UNIT, rest, "unsolicited")
        view = self._stray(rest, "after", view)
        self._last = (UNASKED, b"", b"")
        return data, view

    def _outwait(self, final: bool, view: View) -> bytes:
        """Wait out the longest watchdog a reader may choose since the last byte sent,
        when the suite left something unfinished on purpose and then let it go: at the
        end of a case, after a frame that timed out, or (a lone `!`, a frame without its
        CR) once the unit's own watchdog time has passed without a byte. A packet the
        next frame goes on with, and a frame the next `!` is meant to cut, are not
        waited for. Returns what arrived meanwhile (real time)."""
        link = self.link
        kind = link.left_open(view)
        if not kind or self._waited_out or (final and link.superseded):
            return b""
        profile = link.guard.profile
        idle = link.now - self._sent_until
        let_go = idle >= profile.watchdog_ms * 1_000_000 and kind != OPEN_PACKET
        if not (final or let_go or self._last[0] == TIMED_OUT):
            return b""
        self._waited_out = True
        left = (profile.watchdog_longest_ms * 1_000_000 - idle) / SECOND + MARGIN
        if left <= 0:
            return b""
        with link.spending(Spent.MANUAL):          # the watchdog's time, as a unit may take it
            if link.line is not None:
                link.line.advance(left)
                return b""
            return self.listen(left, stop_early=False)

    def _stray(self, data: bytes, when: str, view: View, *, judged: bool = False) -> View:
        """Bytes no frame asked for, judged (conformance/link/strays.py): a watchdog's
        answer that ends what the suite left open, else a second answer or a late one;
        the view after."""
        kind = self.link.left_open(view)
        ended, stray = judge(data, when, kind, view.checksums, self._last, judged=judged)
        if stray is not None:
            self.violations.append(stray)
        return view.assume(packet=None) if ended and kind == OPEN_PACKET else view
