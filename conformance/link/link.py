"""The suite's Link to a target (docs/suite.md): frames out, responses in, a wire log.

On the embedded emulator the port is a ``gve://`` pyserial object in virtual time:
waiting and timeouts advance the virtual clock, nothing sleeps. On serial and TCP
targets time is real and timeouts come from the baud rate and the command.

Every byte the link writes is framed as a unit would frame it, and every complete frame
is judged by the run's :class:`~conformance.link.safety.Guard` before the first byte
goes out and booked with its answer afterwards: frames built by :meth:`Link.send`, raw
bytes of :meth:`Link.send_raw` (golden replays, noise) and frames changed by an injected
fault alike.

Answers belong to their frame: bytes that arrive before a frame is
sent are logged as unsolicited and never read as its answer; after a frame timed out
the link waits for a quiet line before the next one (real time), so a late answer is
not taken for a later frame's. An answer up to :data:`LATE` after its timeout is
still its frame's, noted as late (:attr:`Link.late`), not a failure: the spec sets no
deadline, and a slow line (a USB adapter's latency timer under load) makes a correct
unit late; later than that it is a hang's, and FAILs whatever the tag.
Bytes after a complete answer are recorded in :attr:`Link.violations` ("answered
twice"), which fail the case that sent the frame, each naming the rule it breaks.

What the suite leaves unfinished on purpose — a lone `!`, a frame without its CR, an open
packet — a watchdog may end with an answer of its own (code 2) at a time the manuals do
not give. Such an answer is the watchdog's, never a second answer to the frame before:
it is judged by the watchdog's rule (our reading answers a lone `!` with nothing, a
frame with 2, and closes no packet by time). Before the next frame (once the suite let
the unfinished bytes reach the unit's own watchdog time, or its last frame timed out)
and at the end of a case, the link waits out the longest watchdog a reader may choose
(the profile's ``watchdog_longest_ms``) since the last byte, so that no such answer is
taken for a later frame's.

Every wait of the link is booked in its time account (conformance/link/account.py):
an exchange's bytes at the baud rate as line time and the rest as the unit's (its
answer, or the motion a command answers at the end of), a wait under what its caller
says it waits for (the suite's own unless told), a timeout and a quiet line as the
suite's own waits.
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Callable, Sequence

from conformance.link.account import Spent, TimeAccount
from conformance.link.faults import FrameFault
from conformance.link.framing import (
    CR,
    HostFrame,
    HostFramer,
    Response,
    frame,
    parse_response,
    readable,
)
from conformance.link.index_read import index_value, read_index
from conformance.link.line_time import MARGIN as MARGIN
from conformance.link.line_time import LineTime
from conformance.link.liveness import Booked, Observed, tell_followers
from conformance.link.safety import Admitted, Guard
from conformance.link.signals import Interrupted
from conformance.link.strays import (
    ANSWERED,
    OPEN_PACKET,
    TIMED_OUT,
    UNASKED,
    Stray,
    judge,
    left_open,
)
from conformance.link.virtual import Rig, line_of
from conformance.protocol.index import Form
from conformance.protocol.view import View, answered_late, late, observe
from conformance.protocol.wire import is_hex_byte
from gve_fixtures.protocol import MAX_FRAME, SECOND, St6
from gve_fixtures.transcript import HOST, UNIT, Record

#: real time: after a frame timed out, how long the line must stay quiet before the next
#: frame (an answer later than this after its timeout could still be misread)
QUIET = 2.5
#: real time: how long after its timeout an answer is still taken as its frame's, noted
#: as late (a loaded USB adapter's line); later than that it is a hang's
LATE = 1.0

class Link:
    def __init__(self, port, guard: Guard, *, address: int = 0, baud: int = 115200,
                 virtual: bool = False, rig: Rig | None = None) -> None:
        self.port = port
        #: the link's clock and time account (the virtual line's clock in virtual time)
        self.time = LineTime(line_of(port) if virtual else None, baud)
        self.address = address
        self.guard = guard
        self._followers = guard.followers()      # who is told each exchange
        self.rig = rig
        #: the unit as the wire shows it (protocol/view.py), fed once per exchange: the
        #: checksum mode, the open packet, the index's form...; the unit's addresses
        #: share it
        self.view = View(addresses=frozenset(guard.addresses))
        self.log: list[Record] = []
        self.frames = 0
        self.violations: list[Stray] = []
        #: real time: answers that came after their timeout, within the quiet the line
        #: keeps before the next frame, taken as their frame's (notes, not violations)
        self.late: list[str] = []
        self._quiet = 0.0        # seconds the line has been quiet since a timeout
        #: when the last frame's bytes began to go out (ns), after any quiet the line kept
        #: for the frame before it: the instant its round trip counts from
        self.wrote_at = 0
        self._faults: list[FrameFault] = []
        self._framer = HostFramer()
        self._unbooked: list[HostFrame] = []     # raw frames whose answer is not read yet
        self._last: tuple[str, bytes, bytes] = (UNASKED, b"", b"")   # state, frame, answer
        self._dropped = False
        self._sent_until = 0      # when the last byte the suite wrote went out (ns)
        self._waited_out = True   # what is left unfinished had its watchdog waited out
        #: a later link of the case took over: what this one left went to a unit that
        #: has heard other frames since (or, on the emulator, is gone)
        self.superseded = False
        #: what the guard said of the frames written last (Guard.admit)
        self._admitted = Admitted()
        #: work of the caller's done once, while the port runs the next frames told
        #: ahead (:meth:`tell`), or by the caller when none are told
        self.meanwhile: Callable[[], None] | None = None

    # -- what the view holds -------------------------------------------------------------
    @property
    def checksums(self) -> bool:
        """Whether the unit reads and writes checksums (the view's mode)."""
        return self.view.checksums

    @checksums.setter
    def checksums(self, on: bool) -> None:
        self.view = self.view.assume(checksums=on)

    @property
    def index_form(self) -> Form | None:
        """The form `@` writes the index in, once read (protocol/index.py)."""
        return self.view.index_form

    @index_form.setter
    def index_form(self, form: Form | None) -> None:
        self.view = self.view.assume(index_form=form)

    # -- time (the link's LineTime) ------------------------------------------------------
    virtual = property(lambda self: self.time.virtual)
    line = property(lambda self: self.time.line)
    now = property(lambda self: self.time.now)
    account = property(lambda self: self.time.account)

    @property
    def round_trip(self) -> dict[str, float]:
        """Real time: the line's round trip as the session measured it (LineTime)."""
        return self.time.round_trip

    @round_trip.setter
    def round_trip(self, measured: dict[str, float]) -> None:
        self.time.round_trip = measured

    @property
    def baud(self) -> int:
        """The line's rate (a case that changes it tells the link: LineTime)."""
        return self.time.baud

    @baud.setter
    def baud(self, rate: int) -> None:
        self.time.baud = rate

    def keep_account(self, account: TimeAccount) -> None:
        self.time.keep_account(account)

    def spending(self, spent: Spent) -> contextlib.AbstractContextManager[None]:
        return self.time.spending(spent)

    def byte_seconds(self, n: int) -> float:
        return self.time.byte_seconds(n)

    def answer_timeout(self, body: str, size: int) -> float:
        """How long the answer to a frame of ``size`` bytes carrying ``body`` may take:
        the frame's and an answer's bytes, a margin, what the command itself takes when it
        answers at its end, and what the line adds (:meth:`line_seconds`)."""
        return self.time.timeout(self.guard.times.answer_seconds(body), size)

    def summed_after(self, body: str) -> bool:
        """Whether the answer to ``body`` carries a checksum: iff the mode is on after
        the command (spec 6, 10 J)."""
        return self.view.summed_after(body)

    def wait(self, seconds: float, spent: Spent = Spent.WAITS) -> bytes:
        """Let ``seconds`` pass, booked under ``spent`` (what the caller waits for: the
        suite's own wait unless it says otherwise); returns whatever arrived meanwhile."""
        self.guard.check_idle()
        self.time.close_exchange()
        with self.spending(spent):
            if self.line is not None:
                self.line.advance(seconds)
                data = self._whole_line(self.port.read(self.port.in_waiting))
            else:
                data = self._listen(seconds, stop_early=False)
        # raw frames not read for an answer: booked as unanswered now, not only when a
        # later frame goes out on this link (there may be none: a `*S` that ends an
        # example must still leave the guard knowing that a packet may be open)
        self._book_unbooked(None)
        rest = self._answers_late(data)
        self.view = self.view.listened()
        if rest:
            self._record(UNIT, rest)
            self._after_answer(rest, "during a wait", judged=True)
        self._last = (UNASKED, b"", b"")
        return data

    def _listen(self, seconds: float, *, stop_early: bool, already: float = 0.0) -> bytes:
        """Real time: read for ``seconds`` (``stop_early``: until the line has been quiet
        that long, ``already`` of it before the call); Ctrl-C ends the wait."""
        end = time.monotonic() + max(0.0, seconds - already)
        data = bytearray()
        while time.monotonic() < end and not self.guard.interrupts.pending:
            self.port.timeout = min(0.05, max(0.0, end - time.monotonic()))
            got = self.port.read(max(1, self.port.in_waiting))
            data += got
            if got and stop_early:
                end = time.monotonic() + seconds
        return self._whole_line(bytes(data))

    def _whole_line(self, data: bytes) -> bytes:
        """``data`` and the rest of the line it ends inside: a unit's bytes arrive one
        after another, so a read that ends while a line is on its way has its beginning
        only; what the unit wrote in one go is judged whole, as it came, never its tail
        as a second or a late answer."""
        if not data or data.endswith(CR) or self.guard.interrupts.pending:
            return data
        self.port.timeout = MARGIN + self.byte_seconds(MAX_FRAME) + self.time.line_seconds()
        return data + self.port.read_until(CR)

    def _pause(self, seconds: float, spent: Spent) -> None:
        """Hold back the next bytes (an injected delay); what arrives stays unread."""
        began = self.time.clock()
        with self.spending(spent):
            if self.line is not None:
                self.line.advance(seconds)
            else:
                time.sleep(seconds)  # real serial/TCP time: the fault is a pause on the wire
        self.time.paused(self.time.clock() - began)

    # -- faults ---------------------------------------------------------------------------
    def inject(self, direction: str, kind: str, **params) -> None:
        """Plan a fault for the next frame ("host") or response ("unit")."""
        self._faults.append(FrameFault(direction, kind, params))

    def _fault(self, direction: str) -> FrameFault | None:
        for i, f in enumerate(self._faults):
            if f.direction == direction:
                return self._faults.pop(i)
        return None

    # -- sending --------------------------------------------------------------------------
    def _record(self, direction: str, data: bytes, comment: str = "") -> None:
        self.log.append(Record(direction, data, self.now, comment))

    def note(self, text: str) -> None:
        self.log.append(Record("=", f"note {text}".encode("ascii", "replace"), self.now))

    def _transmit(self, data: bytes, summed: bool | None) -> list[HostFrame]:
        """Write ``data`` (host faults apply) once the guard judged each frame it completes
        (once, :meth:`Guard.admit`; one told a co-simulator ahead, when told): those frames."""
        self._book_unbooked(None)
        fault = self._fault("host")
        pieces = fault.apply(data) if fault else [(data, 0.0)]
        wire = b"".join(p for p, _ in pieces)
        frames = self._framer.frames(wire, commit=False)
        self.settle()
        ran = getattr(self.port, "ran", None)
        self._admitted = self.guard.admit(frames, summed,
                                          judged=ran is not None and ran(wire))
        self.wrote_at = self.now
        self._framer.frames(wire)
        if fault:
            self.note(f"fault host {fault.kind} {fault.params}")
        self._dropped = not wire
        # a frame held back mid-way waits out the unit's watchdog (spec 3)
        paused = Spent.MANUAL if fault and fault.kind == "delay" else Spent.WAITS
        for piece, pause in pieces:
            if pause:
                self._pause(pause, paused)
            if piece:
                self._write(piece)
        self._sent_until, self._waited_out = self.now, False
        if frames:
            self._last = (UNASKED, frames[-1].wire, b"")
        return frames

    def _write(self, data: bytes) -> None:
        """Write ``data`` unless the run must stop now. The guard judged the frames just
        before (or before an injected delay's pause); a signal that came since must
        still keep them off the line, so the signals are asked at the instant of
        writing, held between the question and the write."""
        ran = getattr(self.port, "ran", None)
        if ran is not None and ran(data):
            # told a co-simulator ahead, it ran them then: no signal keeps them off its
            # line any more, nothing to hold
            self._put(data)
            return
        interrupts = self.guard.interrupts
        with interrupts.writing():
            if not self._admitted.urgent and interrupts.bars(own=self._admitted.own):
                raise Interrupted
            self._put(data)

    def _put(self, data: bytes) -> None:
        self._record(HOST, data)
        self.time.wrote(len(data))
        self.port.write(data)

    def send_raw(self, data: bytes) -> None:
        """Bytes exactly as given (host faults apply). Every frame they complete is
        judged as the unit reads it in the mode the link believes (the guard: every
        reading after a frame that may change the mode) and booked like any other; its
        answer is whatever :meth:`read_response` reads next."""
        self._unbooked = self._transmit(data, self.checksums)

    def send(self, body: str, *, lines: int = 1, answer: bool = True,
             checksum: bool | str = "auto", address: int | None = None,
             timeout: float | None = None) -> Response | None:
        """Send one command frame and read its answer (None when none came in time)."""
        summed = self.checksums if checksum == "auto" else checksum
        address = self.address if address is None else address
        data = frame(body, address, summed)
        self.frames += 1
        sent = self._transmit(data, summed is not False)
        if not answer:
            self._book(sent, None, awaited=False)
            return None
        late = 0.0
        if self._dropped:
            timeout = 0.0            # an injected fault dropped it: no answer can come
        elif timeout is None:
            timeout = self.time.timeout(self._admitted.answer_seconds, len(data))
            late = 0.0 if self.virtual else LATE
        self._unbooked = sent
        # H and W answer when their motion ends: the wait for them is the motion's
        self.time.answered_as = (Spent.MOTION if self._admitted.answer_seconds
                             else Spent.ANSWERS)
        r = self.read_response(timeout, lines, summed=self.summed_after(body), late=late)
        if r is not None:
            r.sent_at = self.wrote_at
        return r

    def send_each(self, bodies: Sequence[str]) -> list[Response | None]:
        """:meth:`send` each frame in turn, in the mode the link believes. A port that can
        take frames it is told ahead (a co-simulator's, docs/cosim.md: `batch`) is told
        them first: what goes on the line, and when, is the same."""
        self.tell(bodies)
        return [self.send(body) for body in bodies]

    def tell(self, bodies: Sequence[str]) -> None:
        """Tell a port that takes frames told ahead (a co-simulator's, docs/cosim.md:
        `batch`) the frames about to be sent with :meth:`send` one after the other, in the
        mode the link believes (any other port is told nothing). Each is still judged,
        sent and read as it comes; a frame not sent as told drops the rest. The link's
        :attr:`meanwhile` work is done here once frames are told, while the port runs
        them."""
        expect = getattr(self.port, "expect", None)
        if expect is None or self._faults or not getattr(self.port, "tells", True):
            return
        bodies = self.guard.told_ahead(bodies, self.address)
        if not bodies:
            return
        framed = [frame(body, self.address, self.checksums) for body in bodies]
        told = [(data, self.answer_timeout(body, len(data))) for body, data in
                zip(bodies, framed, strict=True)]
        work = self.meanwhile
        if work is None:
            expect(told)
        # with work to do meanwhile, the port's reply is read when the link next uses
        # it: the work runs while the port runs the frames
        elif getattr(self.port, "tell", expect)(told):
            self.meanwhile = None
            work()

    @property
    def takes_ahead(self) -> bool:
        """Whether raw frames may be told ahead on this link now (conformance/link/
        ahead.py): its port takes them (a co-simulator's), no fault is planned and no
        frame is half sent."""
        return (getattr(self.port, "expect", None) is not None and not self._faults
                and not self._framer.in_frame)

    def _book(self, frames: list[HostFrame], answer: Response | None, *,
              awaited: bool = True, heard: bool = False) -> None:
        """Book frames with the answer to the last one (the others got none; ``awaited``
        false: one may come later): the view observes each frame once, then the unit's
        followers (Guard.followers) are told the exchange once (``heard``: its answer)."""
        booked = []
        for i, f in enumerate(frames):
            last = i == len(frames) - 1
            r = answer if last else None
            body = f.bodies(self.checksums)[0]
            address = self.address if f.address is None else f.address
            self.view = observe(self.view, body, r, address, awaited=awaited and last)
            booked.append(Booked(body, r, address, self.view))
        if booked or heard:
            at, admitted = self.time.origin + self.wrote_at, self._admitted
            tell_followers(Observed(tuple(booked), self.view, answer, at, heard, admitted.own,
                                    admitted.urgent), *self._followers)

    def _answers_late(self, data: bytes) -> bytes:
        """Give each whole line of ``data`` that came after its frame to the frame it
        answers: the first sent with no answer awaited that may have one (a frame the
        unit did not take as a packet's member); returns the lines nobody's."""
        lines = data.split(CR)
        taken = 0
        for line in lines[:-1]:
            if not self.view.answerable:
                break
            r = parse_response(line + CR, summed=self.checksums)
            after = late(self.view, r) if r is not None and r.code is not None else None
            if after is None:
                break
            owner = answered_late(self.view)
            assert owner is not None
            frame_text = readable(frame(owner.body, owner.address, owner.before.checksums))
            self._record(UNIT, line + CR, f"the answer to {frame_text}, sent before")
            self.view = after
            taken += len(line) + 1
        return data[taken:]

    def left_open(self) -> str:
        """What the suite's bytes so far leave for a watchdog to end (LONE_BANG,
        OPEN_FRAME, OPEN_PACKET), "" when nothing."""
        return left_open(self._framer.partial, self.view.packet_open)

    def _book_unbooked(self, answer: Response | None, *, awaited: bool = False,
                       heard: bool = False) -> None:
        """Book the raw frames sent (:meth:`_book`) with ``answer`` (None: none read)."""
        frames, self._unbooked = self._unbooked, []
        self._book(frames, answer, awaited=awaited, heard=heard)

    def read_index(self, address: int | None = None) -> int | None:
        """The index `@` answers in the form the unit writes it (conformance/link/
        index_read.py; None: no answer, or a refusal)."""
        where = self.address if address is None else address
        value, form = read_index(lambda body: self.send(body, address=where), self.index_form)
        if form is not None:
            self.index_form = form
        return value

    def index_value(self, r: Response) -> int:
        """Value 0 of ``r`` (an answer to `@`) as the index, in the form the unit writes it."""
        return index_value(r, self.index_form)

    def read_response(self, timeout: float | None = None, lines: int = 1, *,
                      summed: bool | None = None, settle: bool = True,
                      late: float = 0.0) -> Response | None:
        """The next answer (``lines`` lines); in real time bytes right behind it are
        taken as a second answer unless ``settle`` is false (the caller may take them as
        :meth:`rest_of_answer`). ``late``: how long after ``timeout`` an answer is still
        taken as this frame's (the quiet the line must keep before the next frame anyway)
        and noted in :attr:`late` rather than lost."""
        timeout = MARGIN if timeout is None else timeout
        raw = bytearray()
        self.port.timeout = timeout
        self._quiet = 0.0
        asked = time.monotonic()
        began = self.time.clock()
        answered_as, self.time.answered_as = self.time.answered_as, Spent.ANSWERS
        for i in range(lines):
            # an answer that began in time is read to its end before it is judged
            chunk = self._whole_line(self.port.read_until(CR))
            if i == 0 and late and not chunk.endswith(CR) \
                    and not self.guard.interrupts.pending:
                self.port.timeout = late
                chunk += self.port.read_until(CR)
                if chunk.endswith(CR):
                    self.late.append(f"{readable(self._last[1]) or 'a frame'} answered "
                                     f"{time.monotonic() - asked:.3f} s after it was sent, "
                                     f"{timeout:.3f} s allowed")
                elif not chunk:
                    self._quiet = late       # of the quiet wait before the next frame
            raw += chunk
            if not chunk.endswith(CR):
                break
            self.port.timeout = MARGIN + self.time.line_seconds()
        data = self._behind_late(bytes(raw), lines)
        # an answer that did not come (or not whole) was waited for to the suite's deadline
        self.time.book_exchange(len(data), answered_as if data.endswith(CR) else Spent.WAITS,
                            began)
        summed = self.checksums if summed is None else summed
        real = parse_response(data, summed=summed, lines=lines) if data else None
        if data:
            self._record(UNIT, data)
            real.received_at = self.now
        answered = real is not None and real.code is not None
        # a frame an injected fault dropped cannot be answered late
        self._last = (ANSWERED if answered else UNASKED if self._dropped else TIMED_OUT,
                      self._last[1], data)
        if settle and not self.virtual and data and self.port.in_waiting:
            self.settle()                        # a second answer right behind the first
        # a frame an injected fault dropped is not a silence of the unit's
        self._book_unbooked(real, awaited=True, heard=not self._dropped)
        r = real
        fault = self._fault("unit")
        if fault is not None:
            self.note(f"fault unit {fault.kind} {fault.params}")
            pieces = fault.apply(data) if data else []
            faulted = b"".join(p for p, _ in pieces)
            r = parse_response(faulted, summed=summed, lines=lines) if faulted else None
            if r is not None:
                r.received_at = self.now
        return r

    def _behind_late(self, data: bytes, lines: int) -> bytes:
        """The answer to the frame just sent, when frames sent before it with no answer
        awaited may have been answered all the same (a unit that did not take one as a
        packet's member): answers keep the order of their frames, so while another
        answer follows at once, the one before it is an earlier frame's
        (:meth:`_answers_late`)."""
        while (lines == 1 and data.endswith(CR) and self.view.answerable
               and not self.guard.interrupts.pending):
            self.port.timeout = MARGIN + self.byte_seconds(MAX_FRAME) + self.time.line_seconds()
            behind = self._whole_line(self.port.read_until(CR))
            if not behind.endswith(CR) or self._answers_late(data):
                return data + behind
            data = behind
        return data

    def rest_of_answer(self, seconds: float = MARGIN) -> bytes:
        """The lines that follow an answer at once, taken as part of it (not as a
        second answer): a unit reading a [D] point otherwise may answer a frame with
        more lines than expected (`>` after `@`, if `@` is remembered)."""
        raw = bytearray()
        self.port.timeout = seconds
        began = self.time.clock()
        while True:
            chunk = self.port.read_until(CR)
            raw += chunk
            if not chunk.endswith(CR):
                break
            self.port.timeout = self.byte_seconds(64)
        self.time.book_exchange(len(raw), Spent.WAITS, began)
        if raw:
            self._record(UNIT, bytes(raw), "the rest of the answer")
        return bytes(raw)

    def settle(self, *, final: bool = False) -> bytes:
        """Take what arrived although nothing was asked, before the next frame (or, with
        ``final``, at the end of a case): after a complete answer it is a second answer
        (a violation), after a timeout a late one (a violation), else unsolicited. In
        real time, after a timeout, wait until the line is quiet first."""
        state = self._last[0]
        self.time.close_exchange()
        data = self._outwait(final)
        kept_quiet = False
        if not self.virtual:
            if state == TIMED_OUT and not self.guard.interrupts.pending:
                with self.spending(Spent.WAITS):
                    data += self._listen(QUIET, stop_early=True, already=self._quiet)
                kept_quiet = not self.guard.interrupts.pending
            elif final:
                with self.spending(Spent.WAITS):
                    data += self._listen(self.time.end_quiet(), stop_early=True)
        self._quiet = 0.0
        waiting = self.port.in_waiting
        if waiting:
            data += self.port.read(waiting)
        data = self._whole_line(data)
        rest = self._answers_late(data)
        if not rest:
            if kept_quiet or data:       # the timed-out frame's answer can come no more
                self._last = (UNASKED, b"", b"")
            return data
        self._record(UNIT, rest, "unsolicited")
        self._after_answer(rest, "after")
        self._last = (UNASKED, b"", b"")
        return data

    def _outwait(self, final: bool) -> bytes:
        """Wait out the longest watchdog a reader may choose since the last byte sent,
        when the suite left something unfinished on purpose and then let it go: at the
        end of a case, after a frame that timed out, or (a lone `!`, a frame without its
        CR) once the unit's own watchdog time has passed without a byte. A packet the
        next frame goes on with, and a frame the next `!` is meant to cut, are not
        waited for. Returns what arrived meanwhile (real time)."""
        kind = self.left_open()
        if not kind or self._waited_out or (final and self.superseded):
            return b""
        profile = self.guard.profile
        idle = self.now - self._sent_until
        let_go = idle >= profile.watchdog_ms * 1_000_000 and kind != OPEN_PACKET
        if not (final or let_go or self._last[0] == TIMED_OUT):
            return b""
        self._waited_out = True
        left = (profile.watchdog_longest_ms * 1_000_000 - idle) / SECOND + MARGIN
        if left <= 0:
            return b""
        with self.spending(Spent.MANUAL):          # the watchdog's time, as a unit may take it
            if self.line is not None:
                self.line.advance(left)
                return b""
            return self._listen(left, stop_early=False)

    def _after_answer(self, data: bytes, when: str, *, judged: bool = False) -> None:
        """Bytes no frame asked for, judged (conformance/link/strays.py): a watchdog's
        answer that ends what the suite left open, else a second answer or a late one."""
        kind = self.left_open()
        ended, stray = judge(data, when, kind, self.checksums, self._last, judged=judged)
        if ended and kind == OPEN_PACKET:
            self.view = self.view.assume(packet=None)
        if stray is not None:
            self.violations.append(stray)

    def poll(self, body: str, until: Callable[[Response], bool], max_seconds: float = 30.0,
             every: float = 0.05, *, send: Callable[[str], Response | None] | None = None,
             spent: Spent = Spent.MOTION) -> Response | None:
        """Send ``body`` until ``until(response)`` holds; the last response, or None.
        ``send``: what sends each frame (a caller that books them), else :meth:`send`;
        the waits between them are booked under ``spent`` (the unit's motion, which
        polls wait the end of, unless the caller says otherwise)."""
        send = self.send if send is None else send
        deadline = self.now + max_seconds * SECOND
        while True:
            r = send(body)
            if r is not None and until(r):
                return r
            if self.now > deadline:
                return None
            self.wait(every, spent)

    def wait_idle(self, max_seconds: float = 60.0) -> bool:
        """Poll SR6 until RUN = 0 (spec 10.3)."""
        r = self.poll("SR6", lambda r: r.ok and idle_st6(r), max_seconds)
        return r is not None

    def transcript_lines(self) -> list[str]:
        return [rec.line() for rec in self.log]


def idle_st6(r: Response) -> bool:
    """Whether an answer to `SR6` (or `F`) shows RUN = 0."""
    text = r.values[0] if r.values else ""
    return is_hex_byte(text) and not int(text, 16) & St6.RUN
