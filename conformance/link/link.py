"""The suite's Link to a target (docs/suite.md): frames out, responses in, a wire log.

On the embedded emulator the port is a ``gve://`` pyserial object in virtual time:
waiting and timeouts advance the virtual clock, nothing sleeps. On serial and TCP
targets time is real and timeouts come from the baud rate.
"""

from __future__ import annotations

import re
import time
from collections.abc import Callable

from conformance.link.faults import Fault
from conformance.link.framing import CR, Response, frame, parse_response
from conformance.link.safety import Guard, SafetyStop
from gve_fixtures.transcript import HOST, UNIT, Record

SECOND = 1_000_000_000
#: processing margin on top of the bytes' own transmission time
MARGIN = 0.25
#: H and W answer when the motion has stopped
SLOW = {"H": 120.0, "W": 600.0}


class Link:
    def __init__(self, port, *, address: int = 0, baud: int = 115200,
                 virtual: bool = False, guard: Guard | None = None,
                 rig=None) -> None:
        self.port = port
        self.address = address
        self.baud = baud
        self.virtual = virtual
        self.guard = guard or Guard(enforce=False, max_travel=0, allow_destructive=True)
        self.rig = rig
        self.checksums = False
        self.log: list[Record] = []
        self.frames = 0
        self._faults: list[Fault] = []
        self._origin = self._clock()
        self.eeprom_backup: dict[int, int] = {}

    # -- time ------------------------------------------------------------------------------
    def _clock(self) -> int:
        if self.virtual:
            return self.port.line.now
        return time.monotonic_ns()

    @property
    def now(self) -> int:
        return self._clock() - self._origin

    def byte_seconds(self, n: int) -> float:
        return n * 10 / self.baud

    def wait(self, seconds: float) -> bytes:
        """Let ``seconds`` pass; returns whatever arrived meanwhile."""
        if self.virtual:
            self.port.line.advance(seconds)
            data = self.port.read(self.port.in_waiting)
        else:
            end = time.monotonic() + seconds
            data = bytearray()
            while time.monotonic() < end:
                self.port.timeout = max(0.0, end - time.monotonic())
                data += self.port.read(max(1, self.port.in_waiting))
            data = bytes(data)
        if data:
            self._record(UNIT, data)
        return data

    def _pause(self, seconds: float) -> None:
        """Hold back the next bytes (an injected delay); what arrives stays unread."""
        if self.virtual:
            self.port.line.advance(seconds)
        else:
            time.sleep(seconds)      # real serial/TCP time: the fault is a pause on the wire

    # -- faults ---------------------------------------------------------------------------
    def inject(self, direction: str, kind: str, **params) -> None:
        """Plan a fault for the next frame ("host") or response ("unit")."""
        self._faults.append(Fault(direction, kind, params))

    def _fault(self, direction: str) -> Fault | None:
        for i, f in enumerate(self._faults):
            if f.direction == direction:
                return self._faults.pop(i)
        return None

    # -- sending --------------------------------------------------------------------------
    def _record(self, direction: str, data: bytes, comment: str = "") -> None:
        self.log.append(Record(direction, data, self.now, comment))

    def note(self, text: str) -> None:
        self.log.append(Record("=", f"note {text}".encode("ascii", "replace"), self.now))

    def send_raw(self, data: bytes) -> None:
        """Bytes exactly as given (host faults apply)."""
        fault = self._fault("host")
        pieces = fault.apply(data) if fault else [(data, 0.0)]
        if fault:
            self.note(f"fault host {fault.kind} {fault.params}")
        for piece, pause in pieces:
            if pause:
                self._pause(pause)
            if piece:
                self._record(HOST, piece)
                self.port.write(piece)

    def send(self, body: str, *, lines: int = 1, answer: bool = True,
             checksum: bool | str = "auto", address: int | None = None,
             timeout: float | None = None) -> Response | None:
        """Send one command frame and read its answer (None when none came in time)."""
        backup = self.guard.check(body)
        for a in backup:
            self._backup(a)
        summed = self.checksums if checksum == "auto" else checksum
        address = self.address if address is None else address
        self.drain_unsolicited()
        data = frame(body, address, summed)
        self.frames += 1
        sent_at = self.now
        self.send_raw(data)
        if not answer:
            return None
        name = body[:1]
        wait = timeout if timeout is not None else SLOW.get(name, MARGIN + self.byte_seconds(
            len(data) + 64))
        # the answer is summed iff the mode is on after the command (spec 6, 10 J)
        after = {"%+": True, "%-": False, "J": False}.get(body, self.checksums)
        r = self.read_response(wait, lines, summed=after)
        if r is None:
            return None
        r.sent_at = sent_at
        self._learn(body, r)
        return r

    def _learn(self, body: str, r: Response) -> None:
        if r.code == 0:
            if body == "%+":
                self.checksums = True
            elif body == "%-" or body == "J":
                self.checksums = False
            self.guard.accepted(body)

    def read_response(self, timeout: float | None = None, lines: int = 1, *,
                      summed: bool | None = None) -> Response | None:
        timeout = MARGIN if timeout is None else timeout
        raw = bytearray()
        self.port.timeout = timeout
        for _ in range(lines):
            chunk = self.port.read_until(CR)
            raw += chunk
            if not chunk.endswith(CR):
                break
            self.port.timeout = MARGIN
        data = bytes(raw)
        if data:
            self._record(UNIT, data)
        fault = self._fault("unit")
        if fault is not None:
            self.note(f"fault unit {fault.kind} {fault.params}")
            pieces = fault.apply(data) if data else []
            data = b"".join(p for p, _ in pieces)
        if not data:
            return None
        r = parse_response(data, summed=self.checksums if summed is None else summed,
                           lines=lines)
        r.received_at = self.now
        return r

    def drain_unsolicited(self) -> bytes:
        """Bytes that arrived although nothing was asked (late or extra answers): they
        are logged, so that they cannot pass for the answer to the next frame."""
        waiting = self.port.in_waiting
        if not waiting:
            return b""
        data = self.port.read(waiting)
        if data:
            self._record(UNIT, data, "unsolicited")
        return data

    def poll(self, body: str, until: Callable[[Response], bool], max_seconds: float = 30.0,
             every: float = 0.05) -> Response | None:
        """Send ``body`` until ``until(response)`` holds; the last response, or None."""
        deadline = self.now + max_seconds * SECOND
        while True:
            r = self.send(body)
            if r is not None and until(r):
                return r
            if self.now > deadline:
                return None
            self.wait(every)

    def wait_idle(self, max_seconds: float = 60.0) -> bool:
        """Poll SR6 until RUN = 0 (spec 10.3)."""
        r = self.poll("SR6", lambda r: bool(r.values) and _hex(r.values[0]) is not None
                      and not _hex(r.values[0]) & 0x40, max_seconds)
        return r is not None

    # -- EEPROM backup ----------------------------------------------------------------------
    def _backup(self, address: int) -> None:
        r = self.send("ER%02X" % address)
        if r is None or r.code != 0 or not r.values:
            raise SafetyStop(f"could not back up EEPROM {address:02X} before writing it")
        self.eeprom_backup[address] = int(r.values[0], 16)
        self.guard.eeprom_touched.add(address)

    def restore_eeprom(self) -> list[str]:
        """Write back every byte the session changed and verify it; returns problems."""
        problems = []
        for address, value in sorted(self.eeprom_backup.items()):
            self.guard.eeprom_touched.add(address)
            self.send("EW%02X,%02X" % (address, value))
            r = self.send("ER%02X" % address)
            if r is None or r.values[:1] != ["%02X" % value]:
                problems.append(f"EEPROM {address:02X} not restored to {value:02X}")
        self.eeprom_backup.clear()
        return problems

    def transcript_lines(self) -> list[str]:
        return [rec.line() for rec in self.log]


def _hex(text: str) -> int | None:
    return int(text, 16) if re.fullmatch(r"[0-9A-F]{2}", text) else None
