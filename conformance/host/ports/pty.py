"""A new pseudo-terminal: the host opens its slave path as it would a serial device; the
relay keeps the master. The slave stays open here too, so that the host may open and
close it at will, and so that the settings the host gives its port can be read back."""

from __future__ import annotations

import contextlib
import os
import termios
import tty

#: termios speed constant -> baud rate
SPEEDS = {getattr(termios, f"B{b}"): b for b in (
    1200, 2400, 4800, 9600, 19200, 38400, 57600, 115200, 230400, 460800, 921600)
    if hasattr(termios, f"B{b}")}
PARITY = {0: "N", termios.PARENB: "E", termios.PARENB | termios.PARODD: "O"}


class PtyPort:
    def __init__(self, baud: int) -> None:
        self.master, self.slave = os.openpty()
        tty.setraw(self.slave)
        attrs = termios.tcgetattr(self.slave)
        speed = next((k for k, v in SPEEDS.items() if v == baud), None)
        if speed is not None:
            attrs[4] = attrs[5] = speed
        attrs[2] = (attrs[2] & ~(termios.CSIZE | termios.PARENB | termios.CSTOPB)) | termios.CS8
        termios.tcsetattr(self.slave, termios.TCSANOW, attrs)
        os.set_blocking(self.master, False)
        self.name = os.ttyname(self.slave)

    def fileno(self) -> int:
        return self.master

    def read(self) -> bytes:
        try:
            return os.read(self.master, 65536)
        except (BlockingIOError, OSError):
            return b""

    def write(self, data: bytes) -> int:
        try:
            return os.write(self.master, data)
        except (BlockingIOError, OSError):
            return 0

    def settings(self) -> str:
        attrs = termios.tcgetattr(self.slave)
        cflag, ospeed = attrs[2], attrs[5]
        bits = {termios.CS5: 5, termios.CS6: 6, termios.CS7: 7, termios.CS8: 8}[
            cflag & termios.CSIZE]
        parity = PARITY.get(cflag & (termios.PARENB | termios.PARODD), "N")
        stop = 2 if cflag & termios.CSTOPB else 1
        return f"{SPEEDS.get(ospeed, ospeed)} {bits}{parity}{stop}"

    def close(self) -> None:
        for fd in (self.master, self.slave):
            with contextlib.suppress(OSError):
                os.close(fd)
