"""Cutting a host's byte stream into frames, keeping the instant of every byte (spec 3).

A frame runs from `!` to CR. Whatever else the host sends is a *fragment*: a frame that
a new `!` (or the end of the run) cut short, bytes outside any frame, or a LF right
after a CR (which units ignore, spec 3 [D]). The framer judges nothing; it only keeps
what the host sent, and when.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from itertools import pairwise

BANG, CR, LF = 0x21, 0x0D, 0x0A
#: an unterminated frame is kept up to this many bytes (the rest is only counted)
KEEP = 4096


@dataclass
class HostFrame:
    """A complete frame: ``raw`` from `!` to the byte before CR, ``times[i]`` the instant
    byte i arrived (ns), ``end`` the instant of its CR."""

    raw: bytes
    times: list[int]
    end: int

    @property
    def start(self) -> int:
        return self.times[0]

    @property
    def pauses(self) -> list[tuple[int, int]]:
        """Each pause between consecutive bytes, CR included, as (from, to) instants."""
        return list(pairwise([*self.times, self.end]))

    @property
    def slowest_gap(self) -> int:
        return max((b - a for a, b in self.pauses), default=0)


@dataclass
class Fragment:
    """Bytes that are not a complete frame: ``kind`` is ``cut`` (a frame that a new `!`
    or the end of the run ended without CR), ``stray`` (bytes outside any frame) or
    ``lf`` (a LF right after a frame's CR)."""

    kind: str
    data: bytes
    start: int
    end: int


@dataclass
class HostFramer:
    """Feed bytes with their arrival instant; collect frames and fragments in order."""

    out: list[HostFrame | Fragment] = field(default_factory=list)
    _raw: bytearray = field(default_factory=bytearray)
    _times: list[int] = field(default_factory=list)
    _after_cr: bool = False
    _stray: bytearray = field(default_factory=bytearray)
    _stray_at: int = 0

    @property
    def in_frame(self) -> bool:
        return bool(self._raw)

    @property
    def partial(self) -> bytes:
        """The bytes of the frame in progress (empty when none)."""
        return bytes(self._raw)

    def last_byte_at(self) -> int | None:
        return self._times[-1] if self._times else None

    def feed_byte(self, byte: int, t: int) -> HostFrame | Fragment | None:
        """One byte; returns the frame or fragment it completed, if any (a fragment cut
        by `!` is returned, the new frame goes on)."""
        done: HostFrame | Fragment | None = None
        if byte == BANG:
            done = self._close_stray() or self._cut(t)
            self._raw, self._times = bytearray(b"!"), [t]
        elif self._raw:
            if byte == CR:
                done = HostFrame(bytes(self._raw), self._times, t)
                self._raw, self._times = bytearray(), []
                self._after_cr = True
                self.out.append(done)
                return done
            if len(self._raw) < KEEP:
                self._raw.append(byte)
                self._times.append(t)
        elif byte == LF and self._after_cr:
            done = Fragment("lf", b"\n", t, t)
        else:
            if not self._stray:
                self._stray_at = t
            self._stray.append(byte)
        self._after_cr = False
        if done is not None:
            self.out.append(done)
        return done

    def _cut(self, t: int) -> Fragment | None:
        if not self._raw:
            return None
        frag = Fragment("cut", bytes(self._raw), self._times[0], t)
        self._raw, self._times = bytearray(), []
        return frag

    def _close_stray(self) -> Fragment | None:
        if not self._stray:
            return None
        frag = Fragment("stray", bytes(self._stray), self._stray_at, self._stray_at)
        self._stray = bytearray()
        return frag

    def finish(self, t: int) -> list[Fragment]:
        """The end of the run: an unfinished frame or stray bytes become fragments."""
        done = [f for f in (self._close_stray(), self._cut(t)) if f is not None]
        self.out += done
        return done
