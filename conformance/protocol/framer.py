"""Cutting a host's byte stream into frames as a unit does (spec 3), keeping the instant
of every byte when asked.

A frame runs from `!` to CR: bytes before `!` are ignored, a `!` restarts an unfinished
frame, CR ends one (a LF after it is noise). Whatever else the host sends is a
*fragment*: a frame that a new `!` (or the end of the run) cut short, bytes outside any
frame, or a LF right after a CR (which units ignore, spec 3 [D]). The framer judges
nothing; it only keeps what the host sent, and when. The same framer serves the suite
as a host (the link and its guard: :meth:`HostFramer.frames`, no instants) and the
suite playing the unit to a host (the relay: :meth:`HostFramer.feed` with instants).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from itertools import pairwise

from conformance.protocol.wire import is_hex_byte

CR, LF, BANG = 0x0D, 0x0A, 0x21
_SPECIAL = re.compile(rb"[!\r]")
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
    def address(self) -> int | None:
        """The digit after `!` (None: not a digit)."""
        digit = self.raw[1:2]
        return int(digit) if digit.isdigit() else None

    @property
    def text(self) -> str:
        """From the byte after the address to the byte before CR."""
        return self.raw[2:].decode("latin-1")

    @property
    def wire(self) -> bytes:
        """The frame's bytes from `!` through CR."""
        return self.raw + b"\r"

    def bodies(self, summed: bool | None) -> list[str]:
        """The frame's possible bodies: without the checksum when ``summed``, as it is
        when not, and both when the checksum mode is not known."""
        head, comma, tail = self.text.rpartition(",")
        stripped = head if comma and is_hex_byte(tail, either_case=True) else None
        if summed is True:
            return [stripped if stripped is not None else self.text]
        if summed is False or stripped is None:
            return [self.text]
        return [self.text, stripped]

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

    def frames(self, data: bytes, *, commit: bool = True, t: int = 0) -> list[HostFrame]:
        """The frames ``data`` completes (fragments are not kept); with ``commit=False``
        the state is unchanged (to judge bytes before they are written)."""
        framer = self if commit else self._trial()
        kept = len(framer.out)
        done = [e for _, e in framer.feed(data, t) if isinstance(e, HostFrame)]
        del framer.out[kept:]
        return done

    def _trial(self) -> HostFramer:
        """A framer in this one's state, with nothing collected yet: what is collected
        grows with the run, and a trial only needs the frame in progress."""
        return HostFramer([], bytearray(self._raw), list(self._times), self._after_cr,
                          bytearray(self._stray), self._stray_at)

    def feed(self, data: bytes, t: int) -> list[tuple[int, HostFrame | Fragment]]:
        """A chunk of bytes that arrived at ``t``; returns what it completed, each with
        the offset in ``data`` just after its last byte (a fragment cut by `!` ends
        before that `!`; the new frame goes on)."""
        events: list[tuple[int, HostFrame | Fragment]] = []
        i, n = 0, len(data)
        while i < n:
            if not self._raw and not self._stray and data[i] == BANG:
                # the usual case first: a whole frame of ordinary length from here
                m = _SPECIAL.search(data, i + 1)
                if m is not None and data[m.start()] == CR and m.start() - i <= KEEP:
                    end = m.start()
                    events.append((end + 1, self._emit(HostFrame(data[i:end],
                                                                 [t] * (end - i), t))))
                    self._after_cr = True
                    i = end + 1
                    continue
            if not self._raw:
                bang = data.find(b"!", i)
                end = n if bang < 0 else bang
                if end > i and self._after_cr and data[i] == LF:
                    events.append((i + 1, self._emit(Fragment("lf", b"\n", t, t))))
                    i += 1
                self._after_cr = False
                if end > i:
                    if not self._stray:
                        self._stray_at = t
                    self._stray += data[i:end]
                if bang < 0:
                    break
                stray = self._close_stray()
                if stray is not None:
                    events.append((bang, stray))
                self._raw, self._times = bytearray(b"!"), [t]
                i = bang + 1
                continue
            m = _SPECIAL.search(data, i)
            end = n if m is None else m.start()
            room = min(end - i, KEEP - len(self._raw))
            if room > 0:
                self._raw += data[i : i + room]
                self._times += [t] * room
            if m is None:
                break
            if data[end] == CR:
                events.append((end + 1, self._emit(HostFrame(bytes(self._raw), self._times, t))))
                self._raw, self._times = bytearray(), []
                self._after_cr = True
            else:
                cut = self._cut(t)
                assert cut is not None
                events.append((end, cut))
                self._raw, self._times = bytearray(b"!"), [t]
            i = end + 1
        return events

    def _emit(self, item: HostFrame | Fragment) -> HostFrame | Fragment:
        self.out.append(item)
        return item

    def _cut(self, t: int) -> Fragment | None:
        if not self._raw:
            return None
        frag = Fragment("cut", bytes(self._raw), self._times[0], t)
        self._raw, self._times = bytearray(), []
        self.out.append(frag)
        return frag

    def _close_stray(self) -> Fragment | None:
        if not self._stray:
            return None
        frag = Fragment("stray", bytes(self._stray), self._stray_at, self._stray_at)
        self._stray = bytearray()
        self.out.append(frag)
        return frag

    def finish(self, t: int) -> list[Fragment]:
        """The end of the run: an unfinished frame or stray bytes become fragments."""
        return [f for f in (self._close_stray(), self._cut(t)) if f is not None]
