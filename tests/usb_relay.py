"""A USB-serial-like line for the real-time tests: a pseudo-terminal the suite opens,
relayed to another serial device (an emulator's pty) as a USB-serial adapter delivers
bytes. Towards the host, bytes wait in a buffer until it holds a full chunk (62 bytes,
an FTDI packet less its two status bytes) or the latency timer (1..16 ms) has run since
the buffer's first byte; every transfer, in both directions, is late by a random jitter
of up to ``jitter_ms`` (order kept). ``stall_ms``: every ``stall_every``-th transfer
towards the host after the first ``stall_from`` is held that much longer, ``stalls``
times at most (an adapter's host under load). ``hold``: a transfer towards the unit that
holds these bytes (a frame) reaches it ``hold_ms`` later than it would (the host under
load the instant it sent that frame: the unit acts on it late, and nothing the host
measured before shows it). A background thread; :meth:`close` ends it."""

from __future__ import annotations

import os
import random
import select
import threading
import time
import tty

#: an FTDI full-speed packet is 64 bytes, two of them status
CHUNK = 62


class UsbRelay:
    def __init__(self, device: str, *, latency_ms: float = 16.0, jitter_ms: float = 2.0,
                 chunk: int = CHUNK, seed: int = 0, stall_every: int = 0,
                 stall_ms: float = 0.0, stall_from: int = 0, stalls: int = 0,
                 hold: bytes = b"", hold_ms: float = 0.0) -> None:
        self.hold, self.hold_for = hold, hold_ms / 1e3
        self.held = 0                   # transfers held so far
        self.latency, self.jitter, self.chunk = latency_ms / 1e3, jitter_ms / 1e3, chunk
        self.stall_every, self.stall, self.stall_from = stall_every, stall_ms / 1e3, stall_from
        self.stalls = stalls            # stalls still to come
        self.pieces = 0                 # transfers towards the host so far
        self._random = random.Random(seed)
        self.master, self._slave = os.openpty()
        tty.setraw(self._slave)
        self.path = os.ttyname(self._slave)
        self.device = os.open(device, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
        tty.setraw(self.device)
        os.set_blocking(self.master, False)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _late(self, after: float) -> float:
        return after + self._random.uniform(0, self.jitter)

    def _run(self) -> None:
        to_device: list[tuple[float, bytes]] = []     # (due, bytes), in order
        to_host: list[tuple[float, bytes]] = []
        buffered, since = bytearray(), 0.0
        while not self._stop.is_set():
            now = time.monotonic()
            dues = [d for d, _ in to_device[:1] + to_host[:1]]
            if buffered:
                dues.append(since + self.latency)
            wait = min([0.01, *(max(0.0, d - now) for d in dues)])
            ready = {fd for fd, _ in _poll((self.master, self.device), wait)}
            now = time.monotonic()
            if self.master in ready:
                data = _read(self.master)
                if data:
                    last = to_device[-1][0] if to_device else now
                    held = self.hold_for if self.hold and self.hold in data else 0.0
                    self.held += held > 0
                    to_device.append((max(last, self._late(now) + held), data))
            if self.device in ready:
                data = _read(self.device)
                if data and not buffered:
                    since = now
                buffered += data
            while len(buffered) >= self.chunk or (buffered and now >= since + self.latency):
                piece, buffered = bytes(buffered[:self.chunk]), buffered[self.chunk:]
                last = to_host[-1][0] if to_host else now
                self.pieces += 1
                held = 0.0
                if self.stalls and self.pieces > self.stall_from and \
                        self.pieces % self.stall_every == 0:
                    held, self.stalls = self.stall, self.stalls - 1
                to_host.append((max(last, self._late(now) + held), piece))
                since = now
            for queue, fd in ((to_device, self.device), (to_host, self.master)):
                while queue and queue[0][0] <= now:
                    os.write(fd, queue.pop(0)[1])

    def close(self) -> None:
        self._stop.set()
        self._thread.join(5)
        for fd in (self.master, self._slave, self.device):
            os.close(fd)


def _poll(fds: tuple[int, ...], seconds: float) -> list[tuple[int, int]]:
    p = select.poll()
    for fd in fds:
        p.register(fd, select.POLLIN)
    return p.poll(seconds * 1e3)


def _read(fd: int) -> bytes:
    try:
        return os.read(fd, 4096)
    except (BlockingIOError, OSError):
        return b""
