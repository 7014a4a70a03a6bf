"""Frames and answers on the wire (spec 3, 4, 6).

A frame is ``!`` address body [``,`` checksum] CR; the checksum is the sum of every byte
from ``!`` up to and including the comma before it, modulo 256, as two hex digits
(``!0A100,`` sums to 0x4F, so the frame is ``!0A100,4F``). An answer is a code (one hex
digit: bit 3 is INTA, bits 0-2 the error) and values, separated by commas, with a
checksum summed the same way in checksum mode: ``0,5C``.
"""

from __future__ import annotations

from dataclasses import dataclass

from gve_fixtures.protocol import INTA_BIT

CR = b"\r"


def checksum(data: bytes) -> int:
    return sum(data) % 256


def frame(address: int, body: str, summed: bool, *, end: bytes = CR) -> bytes:
    head = f"!{address}{body}".encode("ascii")
    if summed:
        head += b","
        head += b"%02X" % checksum(head)
    return head + end


@dataclass(frozen=True)
class Answer:
    code: int                 # 0..7: 0 OK, 1 queue full, 2 watchdog / packet count, ...
    inta: bool                # the unit was interrupted (spec 4)
    values: tuple[str, ...]
    raw: bytes

    def __str__(self) -> str:
        return self.raw.decode("ascii", "replace").rstrip("\r")


def parse(line: bytes, summed: bool, *, trust_checksum: bool = False) -> Answer | None:
    """An answer line (CR removed or not), or None when it is damaged: a byte that is
    not printable ASCII (noise, a broken bit), no code digit, or a checksum that does
    not add up in checksum mode."""
    text = line.rstrip(CR)
    if not text or any(b < 0x20 or b > 0x7E for b in text):
        return None
    fields = text.decode("ascii").split(",")
    head = fields[0]
    if len(head) != 1 or head not in "0123456789ABCDEF":
        return None
    values = fields[1:]
    if summed:
        if not values or len(values[-1]) != 2:
            return None
        summed_ok = values[-1] == "%02X" % checksum(text[:-2])
        if not summed_ok and not trust_checksum:
            return None
        values = values[:-1]
    value = int(head, 16)
    return Answer(value & 7, bool(value & INTA_BIT), tuple(values), bytes(text))
