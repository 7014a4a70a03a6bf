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
twice"), which fail the case that sent the frame.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence

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
from conformance.link.safety import Guard
from conformance.link.virtual import Rig, line_of
from conformance.protocol.wire import is_hex_byte
from gve_fixtures.protocol import SECOND, St6
from gve_fixtures.transcript import HOST, UNIT, Record

#: processing margin on top of the bytes' own transmission time
MARGIN = 0.25
#: real time: after a frame timed out, how long the line must stay quiet before the next
#: frame (an answer later than this after its timeout could still be misread)
QUIET = 2.5
#: real time: how long after its timeout an answer is still taken as its frame's, noted
#: as late (a loaded USB adapter's line); later than that it is a hang's
LATE = 1.0
#: real time: at the end of a case, how long to listen for bytes still on their way
END_QUIET = 0.05

#: answers summed after the command whatever the mode before (spec 6, 10 J)
_MODE_AFTER = {"%+": True, "%-": False, "J": False}

# what the last frame left on the line
_ANSWERED, _TIMED_OUT, _UNASKED = "answered", "timed out", "unasked"


class Link:
    def __init__(self, port, guard: Guard, *, address: int = 0, baud: int = 115200,
                 virtual: bool = False, rig: Rig | None = None) -> None:
        self.port = port
        self.line = line_of(port) if virtual else None   # the clock in virtual time
        self.address = address
        self.baud = baud
        self.virtual = virtual
        self.guard = guard
        self.rig = rig
        self.checksums = False
        #: real time: the line's round trip as the session measured it at its start
        #: (``SessionReport.line``; empty when it was not), for the timing bands
        self.round_trip: dict[str, float] = {}
        self.log: list[Record] = []
        self.frames = 0
        self.violations: list[str] = []
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
        self._last: tuple[str, bytes, bytes] = (_UNASKED, b"", b"")   # state, frame, answer
        self._dropped = False
        self._origin = self._clock()

    # -- time ------------------------------------------------------------------------------
    def _clock(self) -> int:
        if self.line is not None:
            return self.line.now
        return time.monotonic_ns()

    @property
    def now(self) -> int:
        return self._clock() - self._origin

    def byte_seconds(self, n: int) -> float:
        return n * 10 / self.baud

    def answer_timeout(self, body: str, size: int) -> float:
        """How long the answer to a frame of ``size`` bytes carrying ``body`` may take:
        the frame's and an answer's bytes, a margin, what the command itself takes when it
        answers at its end, and what the line adds (:meth:`line_seconds`)."""
        slow = self.guard.answer_seconds(body) or 0.0
        return MARGIN + self.byte_seconds(size + 64) + slow + self.line_seconds()

    def line_seconds(self) -> float:
        """Real time: twice the slowest round trip the session measured (a USB adapter
        holds an answer's bytes up to its latency timer, and may hold its last piece
        that long again); nothing in virtual time or when the line was not measured."""
        return 0.0 if self.virtual else 2 * self.round_trip.get("max_ms", 0.0) / 1e3

    def summed_after(self, body: str) -> bool:
        """Whether the answer to ``body`` carries a checksum: iff the mode is on after
        the command (spec 6, 10 J)."""
        return _MODE_AFTER.get(body, self.checksums)

    def wait(self, seconds: float) -> bytes:
        """Let ``seconds`` pass; returns whatever arrived meanwhile."""
        self.guard.check_idle()
        if self.line is not None:
            self.line.advance(seconds)
            data = self.port.read(self.port.in_waiting)
        else:
            data = self._listen(seconds, stop_early=False)
        if data:
            self._record(UNIT, data)
            self._after_answer(data, "during a wait")
        self._last = (_UNASKED, b"", b"")
        # raw frames not read for an answer: booked as unanswered now, not only when a
        # later frame goes out on this link (there may be none: a `*S` that ends an
        # example must still leave the guard knowing that a packet may be open)
        self._book_unbooked(None)
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
        return bytes(data)

    def _pause(self, seconds: float) -> None:
        """Hold back the next bytes (an injected delay); what arrives stays unread."""
        if self.line is not None:
            self.line.advance(seconds)
        else:
            time.sleep(seconds)      # real serial/TCP time: the fault is a pause on the wire

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
        """Write ``data`` (host faults apply) once the guard has judged every frame it
        completes; returns those frames."""
        self._book_unbooked(None)
        fault = self._fault("host")
        pieces = fault.apply(data) if fault else [(data, 0.0)]
        wire = b"".join(p for p, _ in pieces)
        frames = self._framer.frames(wire, commit=False)
        self.guard.check_frames(frames, summed)
        self.settle()
        self.wrote_at = self.now
        self._framer.frames(wire)
        if fault:
            self.note(f"fault host {fault.kind} {fault.params}")
        self._dropped = not wire
        for piece, pause in pieces:
            if pause:
                self._pause(pause)
            if piece:
                self._write(piece)
        if frames:
            self._last = (_UNASKED, frames[-1].wire, b"")
        return frames

    def _write(self, data: bytes) -> None:
        """Write ``data`` unless the run must stop now. The guard judged the frames before
        the link waited for a quiet line (or paused for an injected delay); a signal that
        came meanwhile must still keep them off the line, so the guard is asked again at
        the instant of writing, with the signals held between the question and the
        write."""
        with self.guard.interrupts.held():
            self.guard.check_idle()
            self._record(HOST, data)
            self.port.write(data)

    def send_raw(self, data: bytes) -> None:
        """Bytes exactly as given (host faults apply). Every frame they complete is
        judged and booked like any other; its answer is whatever :meth:`read_response`
        reads next."""
        self._unbooked = self._transmit(data, None)

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
            self._book(sent, None)
            return None
        late = 0.0
        if timeout is None:
            timeout = self.answer_timeout(body, len(data))
            late = 0.0 if self.virtual else LATE
        self._unbooked = sent
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
        sent and read as it comes; a frame not sent as told drops the rest."""
        expect = getattr(self.port, "expect", None)
        if expect is not None and not self._faults:
            framed = [frame(body, self.address, self.checksums) for body in bodies]
            expect([(data, self.answer_timeout(body, len(data))) for body, data in
                    zip(bodies, framed, strict=True)])

    def _book(self, frames: list[HostFrame], answer: Response | None) -> None:
        """Book frames with the answer to the last one (the others got none)."""
        for i, f in enumerate(frames):
            r = answer if i == len(frames) - 1 else None
            body = f.bodies(self.checksums)[0]
            address = self.address if f.address is None else f.address
            if r is not None and r.ok and address in self.guard.addresses:
                self._learn(body)
            self.guard.accepted(body, r, address)

    def _book_unbooked(self, answer: Response | None) -> None:
        frames, self._unbooked = self._unbooked, []
        self._book(frames, answer)

    def _learn(self, body: str) -> None:
        """The host's belief about the checksum mode follows the commands that set it."""
        if body == "%+":
            self.checksums = True
        elif body in ("%-", "J"):
            self.checksums = False

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
        for i in range(lines):
            chunk = self.port.read_until(CR)
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
            self.port.timeout = MARGIN + self.line_seconds()
        data = bytes(raw)
        summed = self.checksums if summed is None else summed
        real = parse_response(data, summed=summed, lines=lines) if data else None
        if data:
            self._record(UNIT, data)
            real.received_at = self.now
        answered = real is not None and real.code is not None
        # a frame an injected fault dropped cannot be answered late
        self._last = (_ANSWERED if answered else _UNASKED if self._dropped else _TIMED_OUT,
                      self._last[1], data)
        if settle and not self.virtual and data and self.port.in_waiting:
            self.settle()                        # a second answer right behind the first
        self._book_unbooked(real)
        r = real
        fault = self._fault("unit")
        if fault is not None:
            self.note(f"fault unit {fault.kind} {fault.params}")
            pieces = fault.apply(data) if data else []
            faulted = b"".join(p for p, _ in pieces)
            r = parse_response(faulted, summed=summed, lines=lines) if faulted else None
            if r is not None:
                r.received_at = self.now
        if not self._dropped:
            self.guard.answered(real, self._origin + self.wrote_at)
        return r

    def rest_of_answer(self, seconds: float = MARGIN) -> bytes:
        """The lines that follow an answer at once, taken as part of it (not as a
        second answer): a unit reading a [D] point otherwise may answer a frame with
        more lines than expected (`>` after `@`, if `@` is remembered)."""
        raw = bytearray()
        self.port.timeout = seconds
        while True:
            chunk = self.port.read_until(CR)
            raw += chunk
            if not chunk.endswith(CR):
                break
            self.port.timeout = self.byte_seconds(64)
        if raw:
            self._record(UNIT, bytes(raw), "the rest of the answer")
        return bytes(raw)

    def settle(self, *, final: bool = False) -> bytes:
        """Take what arrived although nothing was asked, before the next frame (or, with
        ``final``, at the end of a case): after a complete answer it is a second answer
        (a violation), after a timeout a late one (a violation), else unsolicited. In
        real time, after a timeout, wait until the line is quiet first."""
        state = self._last[0]
        data = b""
        kept_quiet = False
        if not self.virtual:
            if state == _TIMED_OUT and not self.guard.interrupts.pending:
                data = self._listen(QUIET, stop_early=True, already=self._quiet)
                kept_quiet = not self.guard.interrupts.pending
            elif final:
                data = self._listen(END_QUIET, stop_early=True)
        self._quiet = 0.0
        waiting = self.port.in_waiting
        if waiting:
            data += self.port.read(waiting)
        if not data:
            if kept_quiet:               # the timed-out frame's answer can come no more
                self._last = (_UNASKED, b"", b"")
            return b""
        self._record(UNIT, data, "unsolicited")
        self._after_answer(data, "after")
        self._last = (_UNASKED, b"", b"")
        return data

    def _after_answer(self, data: bytes, when: str) -> None:
        state, sent, answer = self._last
        frame_text = readable(sent) or "the last frame"
        if state == _ANSWERED:
            self.violations.append(f"answered twice: {frame_text} got {readable(answer)}, "
                                   f"then {readable(data)} {when}")
        elif state == _TIMED_OUT:
            self.violations.append(f"answered after its timeout: {frame_text} got "
                                   f"{readable(data)} late")

    def poll(self, body: str, until: Callable[[Response], bool], max_seconds: float = 30.0,
             every: float = 0.05, *, send: Callable[[str], Response | None] | None = None
             ) -> Response | None:
        """Send ``body`` until ``until(response)`` holds; the last response, or None.
        ``send``: what sends each frame (a caller that books them), else :meth:`send`."""
        send = self.send if send is None else send
        deadline = self.now + max_seconds * SECOND
        while True:
            r = send(body)
            if r is not None and until(r):
                return r
            if self.now > deadline:
                return None
            self.wait(every)

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
