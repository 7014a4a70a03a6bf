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
not taken for a later frame's. An answer up to the late grace after its timeout
(:data:`~conformance.link.line_time.LATE`) is still its frame's, noted as late
(:attr:`Link.late`), not a failure: the spec sets no deadline, and a slow line (a USB
adapter's latency timer under load) makes a correct unit late; later than that it is
a hang's, and FAILs whatever the tag.
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
    HostFrame,
    HostFramer,
    Response,
    frame,
    parse_response,
)
from conformance.link.index_read import index_value, read_index
from conformance.link.line_time import MARGIN as MARGIN
from conformance.link.line_time import LineTime
from conformance.link.liveness import Booked, Observed, tell_followers
from conformance.link.receiver import Receiver
from conformance.link.safety import Admitted, Guard
from conformance.link.signals import Interrupted
from conformance.link.strays import Stray, left_open
from conformance.link.virtual import Rig, line_of
from conformance.protocol.index import Form
from conformance.protocol.view import View, observe
from conformance.protocol.wire import is_hex_byte
from gve_fixtures.protocol import SECOND, St6
from gve_fixtures.transcript import HOST, Record


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
        #: the receiving side: answers read and given to whom they belong
        self._receiver = Receiver(self)
        #: when the last frame's bytes began to go out (ns), after any quiet the line kept
        #: for the frame before it: the instant its round trip counts from
        self.wrote_at = 0
        self._faults: list[FrameFault] = []
        self._framer = HostFramer()
        self._unbooked: list[HostFrame] = []     # raw frames whose answer is not read yet
        #: an injected fault dropped the last frame: no answer can come
        self.dropped = False
        #: a later link of the case took over: what this one left went to a unit that
        #: has heard other frames since (or, on the emulator, is gone)
        self.superseded = False
        #: what the guard said of the frames written last (Guard.admit)
        self._admitted = Admitted()
        #: work of the caller's done once, while the port runs the next frames told
        #: ahead (:meth:`tell`), or by the caller when none are told
        self.meanwhile: Callable[[], None] | None = None

    @property
    def violations(self) -> list[Stray]:
        """Bytes no frame asked for that break a rule (the receiver's)."""
        return self._receiver.violations

    @property
    def late(self) -> list[str]:
        """Real time: answers that came after their timeout, within the quiet the line
        keeps before the next frame, taken as their frame's (notes, not violations)."""
        return self._receiver.late

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

    def wait(self, seconds: float, spent: Spent = Spent.WAITS,
             meanwhile: Callable[[], None] | None = None) -> bytes:
        """Let ``seconds`` pass, booked under ``spent`` (what the caller waits for: the
        suite's own wait unless it says otherwise); returns whatever arrived meanwhile.
        ``meanwhile``: work of the caller's done while a port that takes a wait ahead (a
        co-simulator's) waits; with any other port it is not done here."""
        self.guard.check_idle()
        launch = getattr(self.port, "launch_wait", None)
        if meanwhile is not None and launch is not None and launch(seconds):
            meanwhile()
        data = self._receiver.during(seconds, spent)
        # raw frames not read for an answer: booked as unanswered now, not only when a
        # later frame goes out on this link (there may be none: a `*S` that ends an
        # example must still leave the guard knowing that a packet may be open)
        self._book_unbooked(None)
        self.view = self._receiver.waited(data, self.view)
        return data

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
    def record(self, direction: str, data: bytes, comment: str = "") -> None:
        """Log ``data`` sent or received now (the receiver logs what it reads here)."""
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
        self.dropped = not wire
        # a frame held back mid-way waits out the unit's watchdog (spec 3)
        paused = Spent.MANUAL if fault and fault.kind == "delay" else Spent.WAITS
        for piece, pause in pieces:
            if pause:
                self._pause(pause, paused)
            if piece:
                self._write(piece)
        self._receiver.sent(frames[-1].wire if frames else None)
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
        self.record(HOST, data)
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
        if self.dropped:
            timeout = 0.0            # an injected fault dropped it: no answer can come
        elif timeout is None:
            timeout = self.time.timeout(self._admitted.answer_seconds, len(data))
            late = self.time.late()
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
            self.tell_port(told, read=True)
        # with work to do meanwhile, the port's reply is read when the link next uses
        # it: the work runs while the port runs the frames
        elif self.tell_port(told, read=False):
            self.meanwhile = None
            work()

    def tell_port(self, told: Sequence[tuple[bytes, float] | tuple[bytes, float, int | None]],
                  *, read: bool) -> bool:
        """Tell the port frames ahead (CosimLine.expect), its reply read now (``read``) or
        when the link next uses the port; whether they were told. The port runs them at
        once: the signals are asked then, as for a write (:meth:`_write`); where one bars
        frames, none is told (each is then barred at its own write)."""
        interrupts = self.guard.interrupts
        with interrupts.writing():
            if interrupts.bars(own=bool(self.guard.own_frames())):
                return False
            return self.port.expect(told) > 0 if read else self.port.tell(told)

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

    def left_open(self, view: View | None = None) -> str:
        """What the suite's bytes so far leave for a watchdog to end (LONE_BANG,
        OPEN_FRAME, OPEN_PACKET), "" when nothing; by ``view`` (the link's unless given)
        whether a packet is open."""
        view = self.view if view is None else view
        return left_open(self._framer.partial, view.packet_open)

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
        data, real, self.view = self._receiver.answer(timeout, lines, summed, late, self.view)
        summed = self.checksums if summed is None else summed
        if settle and not self.virtual and data and self.port.in_waiting:
            self.settle()                        # a second answer right behind the first
        # a frame an injected fault dropped is not a silence of the unit's
        self._book_unbooked(real, awaited=True, heard=not self.dropped)
        fault = self._fault("unit")
        if fault is None:
            return real
        self.note(f"fault unit {fault.kind} {fault.params}")
        faulted = b"".join(p for p, _ in fault.apply(data)) if data else b""
        r = parse_response(faulted, summed=summed, lines=lines) if faulted else None
        if r is not None:
            r.received_at = self.now
        return r

    def rest_of_answer(self, seconds: float = MARGIN) -> bytes:
        """The lines that follow an answer at once, taken as part of it (not as a
        second answer): a unit reading a [D] point otherwise may answer a frame with
        more lines than expected (`>` after `@`, if `@` is remembered)."""
        return self._receiver.rest_of_answer(seconds)

    def settle(self, *, final: bool = False) -> bytes:
        """Take what arrived although nothing was asked, before the next frame (or, with
        ``final``, at the end of a case): after a complete answer it is a second answer
        (a violation), after a timeout a late one (a violation), else unsolicited. In
        real time, after a timeout, wait until the line is quiet first."""
        data, self.view = self._receiver.settle(final, self.view)
        return data

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
