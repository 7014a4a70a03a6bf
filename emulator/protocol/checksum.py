"""Checksums of frames and responses (spec 6): the byte sum mod 256 as two hex digits."""

from __future__ import annotations


def checksum(text: bytes, *, comma: bool = True) -> int:
    """The sum of ``text``'s bytes mod 256. ``text`` ends with the comma that precedes
    the checksum; ``comma=False`` leaves it out (the mutant ``checksum-no-comma``)."""
    if not comma and text.endswith(b","):
        text = text[:-1]
    return sum(text) & 0xFF
