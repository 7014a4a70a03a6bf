"""The suite's own framing (spec 3, 4, 6), written from the spec, not from the emulator.

A frame is ``"!" address body ["," checksum] CR``; a response is
``code *("," value) ["," checksum] CR`` where the code's bit 3 is INTA.
"""

from __future__ import annotations

from dataclasses import dataclass, field

CR = b"\r"


def byte_sum(data: bytes) -> int:
    """The checksum of spec 6: the sum of the bytes mod 256."""
    return sum(data) % 256


def frame(body: str, address: int = 0, checksum: bool | str = False) -> bytes:
    """The bytes of a command frame. ``checksum``: False (none), True (the right one),
    or literal text (a deliberately wrong or malformed one)."""
    head = f"!{address}{body}".encode("latin-1")
    if checksum is False:
        return head + CR
    if checksum is True:
        summed = head + b","
        return summed + b"%02X" % byte_sum(summed) + CR
    return head + b"," + str(checksum).encode("latin-1") + CR


@dataclass
class Response:
    """One answer as the suite reads it."""

    raw: bytes
    lines: list[bytes] = field(default_factory=list)
    code: int | None = None
    inta: bool | None = None
    values: list[str] = field(default_factory=list)
    checksum: str | None = None
    checksum_ok: bool | None = None
    well_formed: bool = False
    sent_at: int = 0
    received_at: int = 0

    @property
    def text(self) -> str:
        return self.raw.decode("latin-1").replace("\r", "\\r")

    def __str__(self) -> str:
        return self.text


def parse_response(raw: bytes, *, summed: bool, lines: int = 1) -> Response:
    """Parse what arrived for one command (``lines`` CR-terminated lines; the last one is
    the response proper, as after `>`)."""
    parts = raw.split(CR)
    got = [p for p in parts[:-1]]
    r = Response(raw=raw, lines=got)
    if len(got) != lines or parts[-1] != b"":
        return r
    last = got[-1]
    text = last.decode("latin-1")
    fields = text.split(",")
    head = fields[0]
    if len(head) != 1 or head not in "0123456789ABCDEF":
        return r
    value = int(head, 16)
    r.code, r.inta = value & 7, bool(value & 8)
    values = fields[1:]
    if summed:
        if not values or len(values[-1]) != 2:
            r.checksum_ok = False
            r.values = values
            return r
        r.checksum = values[-1]
        upto = last[: len(last) - 2]
        r.checksum_ok = r.checksum == "%02X" % byte_sum(upto)
        values = values[:-1]
    r.values = values
    r.well_formed = all(v != "" for v in values) and (not summed or bool(r.checksum_ok))
    return r
