"""pyserial URL handler: ``serial.serial_for_url("gve://?model=GVE84-100")`` after
``import emulator``. A SerialBase on an in-process line in virtual time: writes advance
the clock by the bytes' transmission time, reads wait (virtually) up to the timeout.
``.line`` gives tests and the suite the rig (inputs, switches, power, state)."""

from __future__ import annotations

import time

from serial.serialutil import PortNotOpenError, SerialBase, SerialException

from emulator.link.clock import RealClock
from emulator.link.line import Line, byte_time
from emulator.link.url import parse_url
from gve_fixtures.protocol import SECOND


class Serial(SerialBase):
    BAUDRATES = (9600, 19200, 38400, 57600, 115200, 230400, 460800, 921600)

    def __init__(self, *args, **kwargs) -> None:
        self.line: Line | None = None
        super().__init__(*args, **kwargs)

    def open(self) -> None:
        if self.is_open:
            raise SerialException("Port is already open.")
        if self._port is None:
            raise SerialException("Port must be configured before it can be used.")
        try:
            spec = parse_url(self._port)
            units = spec.build_units()
        except (ValueError, LookupError, ImportError, OSError) as err:
            raise SerialException(f"gve://: {err}") from err
        baud = spec.line_baud(units)
        self._baudrate = baud
        self.line = Line(units, baud, log=spec.log,
                         clock=RealClock() if spec.realtime else None)
        self.is_open = True

    def close(self) -> None:
        if self.line is not None and self.line.log is not None:
            self.line.log.close()
        self.is_open = False

    def _reconfigure_port(self) -> None:
        if self.line is not None and self._baudrate != self.line.baud:
            if self._baudrate <= 0:
                raise ValueError(f"not a baud rate: {self._baudrate}")
            self.line.baud = self._baudrate
            self.line.byte_ns = byte_time(self._baudrate)

    @property
    def in_waiting(self) -> int:
        if not self.is_open or self.line is None:
            raise PortNotOpenError()
        return self.line.in_waiting

    def read(self, size: int = 1) -> bytes:
        if not self.is_open or self.line is None:
            raise PortNotOpenError()
        return self._read(size, None)

    def read_until(self, expected: bytes = b"\n", size: int | None = None) -> bytes:
        if not self.is_open or self.line is None:
            raise PortNotOpenError()
        return self._read(size or 1 << 30, expected)

    def _read(self, size: int, terminator: bytes | None) -> bytes:
        line = self.line
        if line.clock.virtual:
            return line.read(size, self._timeout, terminator)
        # real time: take what is due, then sleep until the next byte or unit event
        deadline = None if self._timeout is None else line.now + round(self._timeout * SECOND)
        out = bytearray()
        while True:
            out += line.read(size - len(out), 0.0, terminator)
            if len(out) >= size or (terminator and out.endswith(terminator)):
                return bytes(out)
            now = line.now
            nxt = [x for x in (line.wake_instant(), deadline) if x is not None]
            if deadline is not None and now >= deadline:
                return bytes(out)
            wait = (min(nxt) - now) / SECOND if nxt else 0.05
            time.sleep(min(max(wait, 0.0), 0.05))

    def write(self, data: bytes) -> int:
        if not self.is_open or self.line is None:
            raise PortNotOpenError()
        return self.line.write(bytes(data))

    def reset_input_buffer(self) -> None:
        if self.line is not None:
            self.line.discard_received()

    def reset_output_buffer(self) -> None:
        pass

    def flush(self) -> None:
        pass
