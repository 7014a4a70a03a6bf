"""Parameter syntax (spec 3): decimal integers with an optional leading '-', hex bytes.

Every parser raises :class:`CommandError` with code 4 (syntax) or 5 (out of range).
"""

from __future__ import annotations

import re

_DEC = re.compile(r"-?[0-9]{1,12}\Z")
_HEX = re.compile(r"[0-9A-Fa-f]{1,2}\Z")
_FLOAT = re.compile(r"-?([0-9]+\.?[0-9]*|\.[0-9]+)([eE][-+]?[0-9]+)?\Z")

SYNTAX = 4
RANGE = 5


class CommandError(Exception):
    """A command refused with an error code (spec 5)."""

    def __init__(self, code: int, why: str = "") -> None:
        super().__init__(why or f"error {code}")
        self.code = code


def fields(params: str, counts: tuple[int, ...]) -> list[str]:
    """Split comma-separated parameters; their number must be one of ``counts``."""
    parts = params.split(",") if params else []
    if len(parts) not in counts:
        raise CommandError(SYNTAX, f"expected {counts} parameters, got {len(parts)}")
    return parts


def dec(text: str, lo: int | None = None, hi: int | None = None) -> int:
    if not _DEC.match(text):
        raise CommandError(SYNTAX, f"not a decimal integer: {text!r}")
    value = int(text)
    if (lo is not None and value < lo) or (hi is not None and value > hi):
        raise CommandError(RANGE, f"{value} outside {lo}..{hi}")
    return value


def hexbyte(text: str, hi: int = 0xFF) -> int:
    if not _HEX.match(text):
        raise CommandError(SYNTAX, f"not a hex byte: {text!r}")
    value = int(text, 16)
    if value > hi:
        raise CommandError(RANGE, f"{value:X} above {hi:X}")
    return value


def decfloat(text: str) -> float:
    if not _FLOAT.match(text):
        raise CommandError(SYNTAX, f"not a decimal number: {text!r}")
    return float(text)
