"""A real serial device (``/dev/ttyUSB1``), for a host on another machine behind a
null-modem cable: 8N1 at the line's baud rate, held alone while the run has it open."""

from __future__ import annotations

import serial

from conformance.link.exclusive import HeldSerial


class DevicePort:
    def __init__(self, path: str, baud: int) -> None:
        try:
            self.port = HeldSerial(path, baud, bytesize=8, parity="N", stopbits=1,
                                   timeout=0, write_timeout=0)
        except serial.SerialException as err:
            raise ValueError(f"cannot open {path}: {err}") from err
        self.name = path

    def fileno(self) -> int:
        return self.port.fileno()

    def read(self) -> bytes:
        return self.port.read(self.port.in_waiting or 1)

    def write(self, data: bytes) -> int:
        try:
            return self.port.write(data) or 0
        except serial.SerialTimeoutException:
            return 0

    def settings(self) -> None:
        return None

    def close(self) -> None:
        self.port.close()
