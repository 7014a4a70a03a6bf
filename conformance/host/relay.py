"""The relay: the suite plays the unit to a host program.

The host's bytes come in on a port (pty, TCP, serial device), are timed as they arrive and
passed on at once to emulated units; the units' answers go back to the host. The units'
line keeps virtual time, which the relay brings up to the wall clock before every move:
the units act in real time, yet the relay never sleeps on them, and an answer is given to
the host no sooner than the line could have carried it at its baud rate. Between the two
a fault may act at one point of the job (line_faults.py). Every byte both ways is recorded
with its instant (recording.py), and each frame is paired with the answer the unit gave
it, so that the host rules (checks.py) and the motion the unit executed (unitview.py) can
be judged from the wire alone. The relay does only what the line needs while it runs;
reading the frames and booking the units' views waits in the booking (booking.py) until a
fault or the end of the run asks for them.

Answers are paired by time: a unit answers at once (spec 2), so an answer's first byte
follows the frame's CR by one byte time; after passing a frame the relay reads the line
that long (in the line's time) for its answer. `H` and `W` answer when the motion has
stopped; their answers, and the watchdog's `2` to an unfinished frame (spec 3), come
later and are taken as they arrive.
"""

from __future__ import annotations

import select
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass

import serial

from conformance.host.booking import Booking
from conformance.host.frame_rules import command_of
from conformance.host.line_faults import Fault
from conformance.host.ports import HostPort
from conformance.host.recording import STALL_NS, Exchange, Recording, Unsolicited
from conformance.host.unitview import UnitView
from conformance.link.virtual import line_of
from conformance.protocol.catalogue import classes
from conformance.protocol.framer import HostFrame, HostFramer
from gve_fixtures.protocol import SECOND

MS = 1_000_000
#: the longest answer line (the two lines of `>` hold a whole frame each)
MAX_LINE = 2 * 96 + 16
#: most answers are this short or shorter (`0,5C`, `0,-1000,2000,50,xx`)
SHORT = 24
#: the longest the relay waits for the host before it looks at the units again
IDLE_S = 0.02
#: how far the line's clock may lag the wall clock before the relay brings it up
LAG = MS // 2
#: commands that answer when the motion has stopped (spec 2)
DEFERRED = classes(deferred=True)


@dataclass
class Outgoing:
    release: int                   # not before this instant
    data: bytes
    exchange: Exchange | None = None
    unsolicited: Unsolicited | None = None


def now() -> int:
    return time.monotonic_ns()


class Relay:
    def __init__(self, port: HostPort, unit: serial.SerialBase, views: list[UnitView],
                 fault: Fault, baud: int) -> None:
        self.port, self.unit, self.views, self.fault = port, unit, views, fault
        self.line = line_of(unit)                  # the gve:// rig and clock
        self.booking = Booking(views)
        self.units = self.booking.units
        self.byte_ns = round(10 * SECOND / baud)
        self.rec = Recording(now())
        self.framer = HostFramer()
        self.held = bytearray()            # the frame in progress, not yet passed on
        self.outq: deque[Outgoing] = deque()
        self.deferred: deque[Exchange] = deque()
        self.from_unit = bytearray()
        self.last_host = self.rec.origin   # when the host last sent anything
        self.last_given = self.rec.origin  # when the host was last given anything
        self._settings: str | None = None
        self._turn_end: int | None = None       # when the relay's last turn ended

    # -- what faults may use (line_faults.Context) --------------------------------------------
    def now(self) -> int:
        return now()

    def vectors(self) -> int:
        return self.booking.vectors()

    def in_packet(self, address: int | None) -> bool:
        view = self.booking.view(address)
        return view is not None and view.packet is not None

    def checksums(self, address: int | None) -> bool:
        view = self.booking.view(address)
        return view is not None and view.checksums

    def note_fault(self, kind: str, detail: str) -> None:
        self.rec.fault(now(), kind, detail)

    def power_on(self, address: int) -> None:
        self._sync()
        self.line.power_on(address)
        self.booking.power_on(address, now())

    def set_input(self, port: int, value: int, address: int) -> None:
        self._sync()
        self.line.set_input(port, value, address)

    # -- the line's clock --------------------------------------------------------------------
    def _sync(self) -> None:
        """Bring the line's virtual clock up to the wall clock (never back: after a frame
        it runs ahead by the frame's own line time, as a real line would be busy). Less
        than ``LAG`` behind is near enough: the units' times are in milliseconds."""
        behind = now() - self.rec.origin - self.line.now
        if behind > LAG:
            self.line.advance(behind / SECOND)

    def _on_line(self) -> int:
        """The wall-clock instant the line has reached."""
        return self.rec.origin + self.line.now

    # -- the loop ---------------------------------------------------------------------------
    def step(self, max_wait: float = IDLE_S) -> None:
        """One turn: wait for the host (or the next thing due), then move every byte."""
        wait = self._wait(max_wait)
        start = now()
        last = self._turn_end                   # late between turns (the thread waited)
        if last is not None and start - last > STALL_NS:
            self.rec.stalls.append((last, start))
        ready, _, _ = select.select([self.port.fileno()], [], [], wait)
        woke = now()
        if woke - start > wait * SECOND + STALL_NS:
            self.rec.stalls.append((start + round(wait * SECOND), woke))
        if ready:
            self.take_host(self.port.read(), woke)
        self._sync()
        self.take_unit()
        self.fault.tick(now(), self)
        self.deliver()
        done = self._turn_end = now()
        if done - woke > STALL_NS:
            self.rec.stalls.append((woke, done))

    def _wait(self, max_wait: float) -> float:
        """Until the next answer is due to the host; the units' own events (an `H`
        answer, the watchdog) are looked at every turn, ``IDLE_S`` at the most apart."""
        if self.outq:
            return max(0.0, min(max_wait, (self.outq[0].release - now()) / SECOND))
        return max_wait

    def finish(self) -> None:
        """The host is gone: take its last bytes, close its unfinished frame."""
        self.take_host(self.port.read(), now())
        self._sync()
        self.take_unit()
        for frag in self.framer.finish(now()):
            self.rec.fragments.append(frag)
        self.booking.settle()

    # -- host -> units ---------------------------------------------------------------------
    def take_host(self, data: bytes, t: int) -> None:
        if not data:
            return
        self.rec.host_bytes(data, t)
        self.last_host = t
        self._sample_settings(t)
        at = 0
        for end, done in self.framer.feed(data, t):
            self.held += data[at:end]
            at = end
            if isinstance(done, HostFrame):
                self._complete(done)
            else:
                self.rec.fragments.append(done)
        self.held += data[at:]
        # the bytes of this chunk go on at once, unless a fault holds a frame back
        if self.held and not (self.framer.in_frame
                              and self.fault.hold(self.framer.partial, self)):
            self._pass(bytes(self.held))
            self.held.clear()

    def _sample_settings(self, t: int) -> None:
        seen = self.port.settings()
        if seen is not None and seen != self._settings:
            self._settings = seen
            self.rec.settings.append((t, seen))

    def _pass(self, data: bytes) -> None:
        self._sync()
        self.unit.write(data)

    def _complete(self, frame: HostFrame) -> None:
        command = command_of(frame.raw, self.units)
        ex = Exchange(len(self.rec.exchanges), frame)
        self.booking.frame(ex)
        self.rec.exchanges.append(ex)
        held, self.held = bytes(self.held), bytearray()
        whole = held.endswith(frame.raw + b"\r")
        if whole and len(held) > len(frame.raw) + 1:   # noise, or a cut frame, before it
            self._pass(held[: len(held) - len(frame.raw) - 1])
        self._sync()
        self.take_unit()                     # whatever came before belongs to no frame
        if whole:
            sent = self.fault.frame(ex, self)
            ex.to_unit = sent
        else:                                # its first bytes went on already
            sent, ex.to_unit = held, frame.raw + b"\r"
        if sent:
            self.unit.write(sent)            # the line's clock is the wall clock's now
        lines = self._answer(command) if sent and sent.endswith(b"\r") else []
        if not lines and command in DEFERRED and sent:
            self.deferred.append(ex)         # booked when its answer comes
            return
        self._answered(ex, lines)

    def _answer(self, command: str | None) -> list[bytes]:
        """The lines the unit answers right away (`>` answers two, spec 8): the first
        byte of an answer is complete one byte time after the frame's CR."""
        first = self._line(self.byte_ns)
        if first is None:
            return []
        if command != ">":
            return [first]
        second = self._line(self.byte_ns)
        return [first] if second is None else [first, second]

    def _line(self, within: int) -> bytes | None:
        """One answer line whose first byte comes within ``within`` ns of line time. One
        read covers a short answer whole; a frame that gets none lets the line's clock
        run that much ahead, which only ever shortens the gaps the units see."""
        cr = self.from_unit.find(b"\r")
        if cr < 0:
            self.unit.timeout = (within + SHORT * self.byte_ns) / SECOND
            got = self.unit.read_until(b"\r")
            if got and not got.endswith(b"\r"):
                self.unit.timeout = (MAX_LINE * self.byte_ns) / SECOND
                got += self.unit.read_until(b"\r")
            self.from_unit += got
            cr = self.from_unit.find(b"\r")
            if cr < 0:
                return None
        line = bytes(self.from_unit[: cr + 1])
        del self.from_unit[: cr + 1]
        return line

    def _answered(self, ex: Exchange, lines: list[bytes]) -> None:
        ex.answer = lines
        ex.answered_at = self._on_line() if lines else None
        self.booking.answered(ex)
        if lines:
            out = self.fault.answer(ex, self)
            if out.data is not None:
                ex.delivered = out.data
                self._enqueue(Outgoing(self._on_line() + round(out.delay * SECOND), out.data,
                                       ex))
        self.fault.after(ex, self)

    # -- units -> host ---------------------------------------------------------------------
    def take_unit(self) -> None:
        """Answers nobody waits for right now: deferred ones (`H`, `W`), the watchdog's."""
        waiting = self.unit.in_waiting
        if waiting:
            self.from_unit += self.unit.read(waiting)
        while (cr := self.from_unit.find(b"\r")) >= 0:
            line = bytes(self.from_unit[: cr + 1])
            del self.from_unit[: cr + 1]
            if self.deferred:
                self._answered(self.deferred.popleft(), [line])
            else:
                u = Unsolicited([line], self._on_line())
                self.rec.unsolicited.append(u)
                self._enqueue(Outgoing(u.t, line, unsolicited=u))

    def _enqueue(self, item: Outgoing) -> None:
        if self.outq:                       # the line to the host is first in, first out
            item.release = max(item.release, self.outq[-1].release)
        self.outq.append(item)

    def deliver(self) -> None:
        """Give the host what is due; bytes it sent before are timed first, so that a
        frame sent before its previous answer shows as such (spec 2)."""
        while self.outq and self.outq[0].release <= now():
            data = self.port.read()          # never blocks
            if data:
                self.take_host(data, now())
                continue
            item = self.outq[0]
            n = self.port.write(item.data)
            if n == 0:
                return                      # the host does not read: try again later
            t = self.last_given = now()
            self.rec.unit_bytes(item.data[:n], t)
            for record in (item.exchange, item.unsolicited):
                if record is not None and record.delivered_at is None:
                    record.delivered_at = t
            if n < len(item.data):
                item.data = item.data[n:]
                continue
            self.outq.popleft()

    # -- running -------------------------------------------------------------------------
    def serve(self, done: Callable[[], bool], silence: float | None,
              limit: float | None) -> str:
        """Relay until ``done()``: "done"; or the host sent nothing for ``silence``
        seconds since it was last sent or given anything: "silent"; or ``limit``
        seconds passed: "limit"."""
        start = now()
        while True:
            self.step()
            if done():
                return "done"
            t = now()
            quiet = t - max(self.last_host, self.last_given)
            if silence is not None and quiet > silence * SECOND and not self.outq:
                return "silent"
            if limit is not None and t - start > limit * SECOND:
                return "limit"
