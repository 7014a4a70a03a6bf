"""The serial line: units sharing it, the host's side of it, and its clock.

Bytes take ``round(1e10 / baud)`` ns each (8N1: ten bits). In virtual time the clock
moves when the host writes (by the bytes' transmission time), when it reads with a
timeout (up to the moment the bytes are there, or the timeout), and on explicit waits;
nothing sleeps. Units answer through ``emit``; answers are serialized at the baud rate
from the instant the unit emits them. Every byte can be logged as a transcript.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Iterable
from pathlib import Path
from typing import IO

from emulator.link.clock import RealClock, VirtualClock
from emulator.motion.arith import NEVER
from emulator.protocol.unit import Unit
from gve_fixtures.protocol import SECOND
from gve_fixtures.transcript import TranscriptWriter


class TimeRangeError(ValueError):
    """An instant beyond what the emulator's clock can reach."""


def _reachable(t: int) -> int:
    if t >= NEVER:
        raise TimeRangeError(
            f"the emulator's time ends {NEVER // SECOND:,} s (about 73 years) after its "
            f"start; {t // SECOND:,} s is beyond it")
    return t


def byte_time(baud: int) -> int:
    return round(10 * SECOND / baud)


class Line:
    def __init__(self, units: Iterable[Unit], baud: int, *,
                 clock: VirtualClock | RealClock | None = None,
                 log: str | Path | IO[str] | None = None, paced: bool = True) -> None:
        self.units = list(units)
        self.baud = baud
        self.clock = clock or VirtualClock()
        # unpaced (a real-time pty without --baud): bytes take no time either way
        self.byte_ns = byte_time(baud) if paced or self.clock.virtual else 0
        # answers to the host, owned here alone: [instant its first byte is complete,
        # bytes, bytes taken]; byte i of a chunk is complete byte_ns after byte i-1
        self._rx: deque[list] = deque()
        self._unit_free = 0          # when the unit->host direction is free again
        self._host_free = 0          # when the host->unit direction is free again
        self.log: TranscriptWriter | None = None
        if log is not None:
            meta = {"title": "emulator wire log",
                    "profiles": " ".join(u.profile.name for u in self.units),
                    "baud": str(baud)}
            self.log = (TranscriptWriter.open(log, meta) if isinstance(log, str | Path)
                        else TranscriptWriter(log, meta))
        for unit in self.units:
            unit.emit = self._emitter(unit)

    # -- time ----------------------------------------------------------------------------
    @property
    def now(self) -> int:
        return self.clock.now()

    def _settle(self, t: int) -> None:
        for unit in self.units:
            unit.advance(t)

    def next_deadline(self) -> int | None:
        best = None
        for unit in self.units:
            d = unit.next_deadline()
            if d is not None and (best is None or d < best):
                best = d
        return best

    def advance(self, seconds: float) -> None:
        """Let ``seconds`` pass (virtual time), handling every unit event on the way."""
        self.advance_to(self.now + round(seconds * SECOND))

    def advance_to(self, t: int) -> None:
        _reachable(t)
        while True:
            d = self.next_deadline()
            if d is None or d > t:
                break
            self.clock.advance_to(d)
            self._settle(d)
        self.clock.advance_to(t)
        self._settle(t)

    def run_until_idle(self, max_seconds: float = 3600.0) -> bool:
        """Advance until no unit has anything scheduled; False if ``max_seconds`` ran out."""
        limit = self.now + round(max_seconds * SECOND)
        while True:
            d = self.next_deadline()
            if d is None:
                return True
            if d > limit:
                self.advance_to(limit)
                return False
            self.advance_to(d)

    # -- host -> units ----------------------------------------------------------------------
    def write(self, data: bytes) -> int:
        start = max(self.now, self._host_free)
        first = start + self.byte_ns
        _reachable(start + len(data) * self.byte_ns)
        if self.log is not None:
            self.log.host(data, first)
        for unit in self.units:
            if unit.hears(self.baud):
                unit.receive(data, first, self.byte_ns)
        self._host_free = start + len(data) * self.byte_ns
        if self.clock.virtual:
            self.advance_to(self._host_free)
        return len(data)

    # -- units -> host -------------------------------------------------------------------------
    def _emitter(self, unit: Unit):
        """What ``unit`` sends: lost when its UART runs at another rate than the line."""
        def emit(data: bytes, t: int) -> None:
            if unit.hears(self.baud):
                self._emit(data, t)
        return emit

    def _emit(self, data: bytes, t: int) -> None:
        start = max(t, self._unit_free)
        b = self.byte_ns
        self._rx.append([start + b, data, 0])
        self._unit_free = start + len(data) * b
        if self.log is not None:
            self.log.unit(data, start + b)

    def _ready(self, first: int, data: bytes, now: int) -> int:
        """How many bytes of a chunk whose first byte is complete at ``first`` are by now."""
        b = self.byte_ns
        return len(data) if not b else min(len(data), (now - first) // b + 1)

    def _ready_count(self, now: int) -> int:
        n = 0
        for first, data, taken in self._rx:
            if first > now:
                break
            ready = self._ready(first, data, now)
            n += ready - taken
            if ready < len(data):
                break
        return n

    @property
    def in_waiting(self) -> int:
        now = self.now
        if not self.clock.virtual:
            self._settle(now)
        return self._ready_count(now)

    def _take(self, size: int, terminator: bytes | None) -> bytes:
        now, rx = self.now, self._rx
        if not rx or rx[0][0] > now:
            return b""                 # no byte complete yet (a read's usual first look)
        out = bytearray()
        while rx and len(out) < size:
            chunk = rx[0]
            first, data, taken = chunk
            if first > now:
                break
            ready = self._ready(first, data, now)
            end = min(ready, taken + size - len(out))
            if terminator:
                k = data.find(terminator, taken, end)
                if k >= 0:
                    end = k + len(terminator)
            out += data[taken:end]
            chunk[2] = end
            if end == len(data):
                rx.popleft()
            if end < ready or (terminator and out.endswith(terminator)) or ready < len(data):
                break
        return bytes(out)

    def _complete_at(self, size: int, terminator: bytes | None) -> int | None:
        """The instant the request (``size`` bytes or the terminator) is complete, if the
        bytes are already on their way."""
        b, need = self.byte_ns, size
        for first, data, taken in self._rx:
            avail = len(data) - taken
            if terminator:
                k = data.find(terminator, taken)
                if k >= 0 and k - taken < need:
                    return first + k * b
            if avail >= need:
                return first + (taken + need - 1) * b
            need -= avail
        return None

    def read(self, size: int = 1, timeout: float | None = 0.0,
             terminator: bytes | None = None) -> bytes:
        """Up to ``size`` bytes (stopping after ``terminator``), waiting at most
        ``timeout`` seconds of (virtual) time for them."""
        if not self.clock.virtual:
            self._settle(self.now)
            return self._take(size, terminator)
        deadline = None if timeout is None else _reachable(self.now + round(timeout * SECOND))
        out = bytearray()
        while True:
            out += self._take(size - len(out), terminator)
            if len(out) >= size or (terminator and out.endswith(terminator)):
                return bytes(out)
            ready = self._complete_at(size - len(out), terminator)
            event = self.next_deadline()
            t = event if ready is None else ready if event is None else min(ready, event)
            if t is None or (deadline is not None and t > deadline):
                if deadline is not None:
                    self.advance_to(deadline)
                    out += self._take(size - len(out), terminator)
                return bytes(out)
            if event is None or t < event:     # no unit acts before the bytes are there
                self.clock.advance_to(t)
                self._settle(t)
            else:
                self.advance_to(t)

    def take_timed(self) -> list[tuple[int, bytes]]:
        """Every byte complete by now and not taken yet, in runs: (the instant the run's
        first byte is complete, its bytes), each next byte of a run ``byte_ns`` later
        (the co-simulation's ``rx`` lines, docs/cosim.md)."""
        now, rx, out = self.now, self._rx, []
        while rx and rx[0][0] <= now:
            chunk = rx[0]
            first, data, taken = chunk
            ready = self._ready(first, data, now)
            if ready > taken:
                out.append((first + taken * self.byte_ns, data[taken:ready]))
                chunk[2] = ready
            if ready < len(data):
                break
            rx.popleft()
        return out

    def next_byte_at(self, value: bytes) -> int | None:
        """The instant the next unread byte ``value`` is complete (None: none is on its
        way)."""
        for first, data, taken in self._rx:
            k = data.find(value, taken)
            if k >= 0:
                return first + k * self.byte_ns
        return None

    def take_ready(self) -> bytes:
        """Real time: every byte due by now (the server writes them to its port)."""
        self._settle(self.now)
        return self._take(1 << 30, None) if self._rx else b""

    def read_until(self, terminator: bytes = b"\r", size: int = 4096,
                   timeout: float | None = 0.0) -> bytes:
        return self.read(size, timeout, terminator)

    def next_arrival(self) -> int | None:
        """The instant the next unread byte is complete, or None when none is coming."""
        if not self._rx:
            return None
        first, _, taken = self._rx[0]
        return first + taken * self.byte_ns

    def discard_received(self) -> None:
        """Forget every answer not yet read (pyserial's reset_input_buffer)."""
        self._rx.clear()

    def wake_instant(self) -> int | None:
        """The next instant anything happens on the line: a byte for the host or a
        unit's event."""
        due = [x for x in (self.next_arrival(), self.next_deadline()) if x is not None]
        return min(due) if due else None

    # -- the rig -------------------------------------------------------------------------------
    def unit(self, address: int | None = None) -> Unit:
        if address is None:
            return self.units[0]
        for u in self.units:
            if address in u.addresses:
                return u
        raise KeyError(f"no unit at address {address}")

    def set_input(self, port: int, value: int, address: int | None = None) -> None:
        self.unit(address).set_input(port, value, self.now)

    def set_switch(self, axis: str, position: int | None, address: int | None = None) -> None:
        self.unit(address).set_switch(axis, position)

    def set_rate_switch(self, position: int | None, address: int | None = None) -> None:
        self.unit(address).set_rate_switch(position)

    def power_on(self, address: int | None = None) -> None:
        units = self.units if address is None else [self.unit(address)]
        for u in units:
            u.power_on(self.now)

    def state(self, address: int | None = None) -> dict:
        return self.unit(address).snapshot(self.now)

    def pulses(self, t0: int = 0, t1: int | None = None, address: int | None = None
               ) -> list[tuple[int, int]]:
        """The step train of a unit's stepper core in [t0, t1) (default: up to now), as
        (instant in ns on this line's clock, mask): bit i = axis i stepped, bit 4+i = it
        stepped backwards. For pictures of the motion; the suite judges positions."""
        times, masks = self.unit(address).device.motion.pulses(t0, self.now if t1 is None
                                                               else t1)
        return list(zip(times.tolist(), masks.tolist(), strict=True))

    def outputs(self, address: int | None = None) -> int:
        return int(self.state(address)["outputs"], 16)

    def spindle(self, address: int | None = None) -> int:
        return int(self.state(address)["spindle"])
