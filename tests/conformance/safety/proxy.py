"""A man in the middle on a pseudo-terminal: the suite opens :attr:`Proxy.path`; every
byte goes on to a unit's port (``python -m emulator --pty``) and back. The proxy records
every frame the host sends and every answer, with instants, and can play a hostile unit
(:data:`HOSTILE`: answers dropped, doubled, late, replaced) or act when a frame arrives
(``on_frame``: e.g. deliver SIGINT to the suite). Real time, loopback only."""

from __future__ import annotations

import contextlib
import heapq
import json
import os
import select
import subprocess
import sys
import termios
import threading
import time
import tty
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field

from tests.processes import stop

#: a unit's answer (one line, CR included) -> (delay in seconds, bytes) to send instead
Transform = Callable[[bytes], list[tuple[float, bytes]]]

HOSTILE: dict[str, Transform] = {
    "silent": lambda answer: [],
    "twice": lambda answer: [(0.0, answer), (0.0, answer)],
    "garbage": lambda answer: [(0.0, b"\x00\xff#?" + answer[::-1].replace(b"\r", b"") + b"\r")],
    "markup": lambda answer: [(0.0, answer[:-1] + b",<b>x</b>\x00]]></pre><script>\x07\r")],
    "late": lambda answer: [(2.0, answer)],
}


def _raw(fd: int) -> None:
    tty.setraw(fd)
    attrs = termios.tcgetattr(fd)
    attrs[3] &= ~termios.ECHO
    termios.tcsetattr(fd, termios.TCSANOW, attrs)


@dataclass
class Proxy:
    unit_path: str
    transform: Transform | None = None
    on_frame: Callable[[int, bytes], None] | None = None
    frames: list[tuple[float, bytes]] = field(default_factory=list)    # host -> unit
    answers: list[tuple[float, bytes]] = field(default_factory=list)   # unit -> host

    def __post_init__(self) -> None:
        self._master, slave = os.openpty()
        _raw(slave)
        self.path = os.ttyname(slave)
        self._slave = slave
        self._unit = os.open(self.unit_path, os.O_RDWR | os.O_NOCTTY)
        _raw(self._unit)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._loop, daemon=True)
        self._thread.start()

    def _loop(self) -> None:
        host, unit = b"", b""
        later: list[tuple[float, int, bytes]] = []
        n = 0
        while not self._stop.is_set():
            wait = 0.05 if not later else max(0.0, min(0.05, later[0][0] - time.monotonic()))
            ready, _, _ = select.select([self._master, self._unit], [], [], wait)
            if self._master in ready:
                data = self._read(self._master)
                host += data
                while b"\r" in host:
                    line, _, host = host.partition(b"\r")
                    start = line.rfind(b"!")
                    if start >= 0:
                        self.frames.append((time.monotonic(), line[start:] + b"\r"))
                        if self.on_frame:
                            self.on_frame(len(self.frames) - 1, line[start:] + b"\r")
                os.write(self._unit, data)
            if self._unit in ready:
                unit += self._read(self._unit)
                while b"\r" in unit:
                    line, _, unit = unit.partition(b"\r")
                    answer = line + b"\r"
                    self.answers.append((time.monotonic(), answer))
                    pieces = self.transform(answer) if self.transform else [(0.0, answer)]
                    for delay, piece in pieces:
                        n += 1
                        heapq.heappush(later, (time.monotonic() + delay, n, piece))
            while later and later[0][0] <= time.monotonic():
                os.write(self._master, heapq.heappop(later)[2])

    @staticmethod
    def _read(fd: int) -> bytes:
        try:
            return os.read(fd, 4096)
        except OSError:
            return b""

    def ask(self, frame: bytes) -> bytes:
        """Send one frame as another host would (before the suite opens the port) and
        read its answer."""
        fd = os.open(self.path, os.O_RDWR | os.O_NOCTTY)
        try:
            os.write(fd, frame)
            answer = b""
            while not answer.endswith(b"\r"):
                ready, _, _ = select.select([fd], [], [], 5)
                if not ready:
                    break
                answer += os.read(fd, 64)
            return answer
        finally:
            os.close(fd)

    def sent(self) -> list[bytes]:
        return [f for _, f in self.frames]

    def close(self) -> None:
        self._stop.set()
        self._thread.join(5)
        for fd in (self._master, self._slave, self._unit):
            with contextlib.suppress(OSError):
                os.close(fd)


class Emulator:
    """``python -m emulator --pty`` with its control channel (`state`)."""

    def __init__(self, *args: str) -> None:
        self.proc = subprocess.Popen([sys.executable, "-m", "emulator", "--pty", *args],
                                     stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     stderr=subprocess.DEVNULL, text=True)
        self.path = self.proc.stdout.readline().strip()

    def state(self) -> dict:
        self.proc.stdin.write("state\n")
        self.proc.stdin.flush()
        return json.loads(self.proc.stdout.readline())

    def control(self, line: str) -> str:
        self.proc.stdin.write(line + "\n")
        self.proc.stdin.flush()
        return self.proc.stdout.readline().strip()

    def close(self) -> None:
        stop(self.proc)


@contextlib.contextmanager
def unit_behind_proxy(*emulator_args: str, transform: Transform | None = None,
                      on_frame: Callable[[int, bytes], None] | None = None,
                      ) -> Iterator[tuple[Emulator, Proxy]]:
    emu = Emulator(*emulator_args)
    proxy = Proxy(emu.path, transform=transform, on_frame=on_frame)
    try:
        yield emu, proxy
    finally:
        proxy.close()
        emu.close()
