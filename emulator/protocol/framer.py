"""Cutting the byte stream into frames (spec 3) with the watchdog.

Bytes before '!' are ignored; a '!' inside an unfinished frame starts a new frame (the
old one is dropped without an answer); CR ends a frame; an LF after it is noise before
the next '!'. If a frame has started and its next byte does not come within the
watchdog time, the frame is dropped: :meth:`Framer.expire` gives its first bytes so that
the unit answers error 2 (nothing when only the '!' arrived).

The framer never holds more than its limit (:data:`MAX_FRAME` bytes) of a frame: beyond that it
keeps only the byte sum and the last three bytes, which is all a checksum needs, so a
stream without CR costs constant memory, and each byte is looked at once.
"""

from __future__ import annotations

import re
from typing import NamedTuple

from gve_fixtures.protocol import MAX_FRAME

_NEXT = re.compile(rb"[!\r]")


class Frame(NamedTuple):
    """A complete frame without its CR. ``raw`` is the whole frame when ``length`` is at
    most MAX_FRAME, else its first MAX_FRAME bytes; ``total`` is the sum of every byte
    (mod 256) and ``tail`` the last three bytes."""

    raw: bytes
    length: int
    total: int
    tail: bytes
    limit: int = MAX_FRAME        # the longest frame the unit takes whole

    @property
    def too_long(self) -> bool:
        return self.length > self.limit


class Framer:
    def __init__(self, watchdog_ns: int | None, limit: int = MAX_FRAME) -> None:
        self.watchdog_ns = watchdog_ns        # None: the watchdog never fires
        self.limit = limit                    # bytes of a frame the unit holds
        self.buf: bytearray | None = None     # None: no frame open
        self.last = 0                         # instant of the frame's last byte
        self._length = 0                      # bytes beyond MAX_FRAME: counted, summed,
        self._extra = 0                       # and the last three kept
        self._tail = b""

    @property
    def open(self) -> bool:
        return self.buf is not None

    def deadline(self) -> int | None:
        if self.buf is None or self.watchdog_ns is None:
            return None
        return self.last + self.watchdog_ns

    def expire(self, t: int) -> tuple[bytes, int] | None:
        """Drop the open frame if its watchdog ran out by ``t``: (its first bytes, instant)."""
        deadline = self.deadline()
        if deadline is None or t < deadline:
            return None
        head = bytes(self.buf or b"")
        self.buf = None
        return head, deadline

    def reset(self) -> None:
        self.buf = None

    def _start(self, instant: int) -> None:
        self.buf = bytearray(b"!")
        self.last = instant
        self._length, self._extra, self._tail = 1, 0, b""

    def _add(self, data: bytes) -> None:
        if not data:
            return
        buf = self.buf
        assert buf is not None
        room = self.limit - len(buf)
        if room > 0:
            buf += data[:room]
        if len(data) > room:
            beyond = data[room:]
            self._extra = (self._extra + sum(beyond)) & 0xFF
            self._tail = (self._tail + beyond[-3:])[-3:]
        self._length += len(data)

    def _finish(self) -> Frame:
        raw = bytes(self.buf or b"")
        self.buf = None
        if self._length <= self.limit:
            return Frame(raw, self._length, 0, b"", self.limit)
        tail = (raw + self._tail)[-3:]
        return Frame(raw, self._length, (sum(raw) + self._extra) & 0xFF, tail, self.limit)

    def step(self, data: bytes, i: int, t: int, byte_ns: int) -> tuple[Frame | None, int, int]:
        """Consume bytes from index ``i`` up to the end of the next frame.

        Returns (the frame or None, the index after it, the CR's instant). Byte ``k``
        of ``data`` is complete at ``t + k * byte_ns``."""
        n = len(data)
        if self.buf is None:
            # the common case first: a whole frame of ordinary length in this chunk
            j = data.find(b"!", i)
            if j < 0:
                return None, n, 0
            found = _NEXT.search(data, j + 1)
            if found is not None and data[found.start()] == 0x0D \
                    and found.start() - j <= self.limit:
                cr = found.start()
                return Frame(data[j:cr], cr - j, 0, b"", self.limit), cr + 1, t + cr * byte_ns
        while i < n:
            if self.buf is None:
                j = data.find(b"!", i)
                if j < 0:
                    return None, n, 0
                self._start(t + j * byte_ns)
                i = j + 1
                continue
            found = _NEXT.search(data, i)
            if found is None:
                self._add(data[i:])
                self.last = t + (n - 1) * byte_ns
                return None, n, 0
            j = found.start()
            if data[j] == 0x21:                   # '!': the unfinished frame is dropped
                self._start(t + j * byte_ns)
                i = j + 1
                continue
            self._add(data[i:j])
            return self._finish(), j + 1, t + j * byte_ns
        return None, n, 0
