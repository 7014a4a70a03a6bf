"""Cutting the byte stream into frames (spec 3) with the watchdog.

Bytes before '!' are ignored; a '!' inside an unfinished frame starts a new frame (the
old one is dropped without an answer); CR ends a frame; an LF after it is noise before
the next '!'. If a frame has started and its next byte does not come within the
watchdog time, the frame is dropped: :meth:`Framer.expire` reports its address byte so
that the unit answers error 2 (nothing when only the '!' arrived).
"""

from __future__ import annotations


class Framer:
    def __init__(self, watchdog_ns: int | None) -> None:
        self.watchdog_ns = watchdog_ns        # None: the watchdog never fires
        self.buf: bytearray | None = None
        self.last = 0                        # instant of the frame's last byte

    def deadline(self) -> int | None:
        if self.buf is None or self.watchdog_ns is None:
            return None
        return self.last + self.watchdog_ns

    def expire(self, t: int) -> tuple[bytes, int] | None:
        """Drop the open frame if its watchdog ran out by ``t``: (frame so far, instant)."""
        deadline = self.deadline()
        if deadline is None or t < deadline:
            return None
        frame, self.buf = bytes(self.buf or b""), None
        return frame, deadline

    def reset(self) -> None:
        self.buf = None

    def step(self, data: bytes, i: int, t: int, byte_ns: int) -> tuple[bytes | None, int, int]:
        """Consume bytes from index ``i`` up to the end of the next frame.

        Returns (frame without its CR or None, the index after it, the CR's instant).
        Byte ``k`` of ``data`` is complete at ``t + k * byte_ns``."""
        n = len(data)
        while i < n:
            if self.buf is None:
                j = data.find(b"!", i)
                if j < 0:
                    return None, n, 0
                self.buf = bytearray(b"!")
                self.last = t + j * byte_ns
                i = j + 1
                continue
            cr = data.find(b"\r", i)
            bang = data.find(b"!", i)
            if bang >= 0 and (cr < 0 or bang < cr):
                self.buf = bytearray(b"!")        # restart: the unfinished frame is dropped
                self.last = t + bang * byte_ns
                i = bang + 1
                continue
            if cr < 0:
                self.buf += data[i:]
                self.last = t + (n - 1) * byte_ns
                return None, n, 0
            frame = bytes(self.buf) + data[i:cr]
            self.buf = None
            return frame, cr + 1, t + cr * byte_ns
        return None, n, 0
