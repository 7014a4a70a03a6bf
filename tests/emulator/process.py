"""`python -m emulator` as a separate process for the real-time tests: its first line
(the port), its control channel (replies read line by line from the raw pipe, so two
replies that arrive together are two lines), and a rig whose time is the wall clock."""

from __future__ import annotations

import json
import os
import select
import subprocess
import sys
import time

import serial


class Emulator:
    """The emulator process, its first stdout line, and its control channel."""

    def __init__(self, *args: str, stdin: int | None = subprocess.PIPE,
                 module: str = "emulator") -> None:
        self.proc = subprocess.Popen(
            [sys.executable, "-m", module, *args], stdin=stdin,
            stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        self._pending = b""
        self.first = self.readline(20.0)

    def readline(self, timeout: float) -> str:
        """The next line on standard output, waiting at most ``timeout`` seconds."""
        deadline = time.monotonic() + timeout
        fd = self.proc.stdout.fileno()
        while b"\n" not in self._pending:
            left = deadline - time.monotonic()
            assert left > 0 and select.select([fd], [], [], left)[0], \
                f"the emulator printed no line within {timeout} s"
            chunk = os.read(fd, 65536)
            assert chunk, "the emulator closed its standard output"
            self._pending += chunk
        line, _, self._pending = self._pending.partition(b"\n")
        return line.decode().strip()

    def send(self, text: str) -> None:
        """Raw bytes on the control channel (no newline added)."""
        self.proc.stdin.write(text.encode())
        self.proc.stdin.flush()

    def control(self, text: str) -> str:
        self.send(text + "\n")
        return self.readline(10.0)

    def state(self) -> dict:
        return json.loads(self.control("state"))

    def stop(self) -> int:
        self.proc.terminate()
        return self.proc.wait(10)

    def stderr(self) -> str:
        return self.proc.stderr.read().decode() if self.proc.stderr else ""


class RealRig:
    """Time passes for real; the rig's hands are the control channel."""

    def __init__(self, emu: Emulator, port: serial.Serial) -> None:
        self.emu, self.port = emu, port

    @property
    def now(self) -> int:
        return time.monotonic_ns()

    def advance(self, seconds: float) -> None:
        # wait on the port itself: anything arriving meanwhile stays readable
        deadline = time.monotonic() + seconds
        while (left := deadline - time.monotonic()) > 0:
            if select.select([self.port.fileno()], [], [], left)[0]:
                return

    def set_input(self, port: int, value: int) -> None:
        assert self.emu.control(f"in {port} {value:02X}") == "ok"

    def outputs(self) -> int:
        return int(self.emu.state()["outputs"], 16)

    def spindle(self) -> int:
        return self.emu.state()["spindle"]

    def power_on(self) -> None:
        assert self.emu.control("power-on") == "ok"
