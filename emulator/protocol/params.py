"""Parameter syntax and ranges (spec 3).

A frame is checked whole for syntax first (the count and the format of every field:
error 4), then for ranges (error 5): a handler parses every field with the functions
here before it calls :func:`within` on any of them. Decimal and hexadecimal fields take
any number of digits and are then range-checked like any value.
"""

from __future__ import annotations

import re

from gve_fixtures.protocol import ErrorCode

_DEC = re.compile(r"-?[0-9]+\Z")
_HEX = re.compile(r"[0-9A-Fa-f]+\Z")
_FLOAT = re.compile(r"-?[0-9]+(\.[0-9]+)?([eE][-+]?[0-9]+)?\Z")


class CommandError(Exception):
    """A command refused with an error code (spec 5); nothing of it was executed."""

    def __init__(self, code: ErrorCode, why: str = "") -> None:
        super().__init__(why or f"error {int(code)}")
        self.code = code


def fields(params: str, counts: tuple[int, ...]) -> list[str]:
    """Split comma-separated parameters; their number must be one of ``counts``."""
    parts = params.split(",") if params else []
    if len(parts) not in counts:
        raise CommandError(ErrorCode.SYNTAX, f"expected {counts} parameters, got {len(parts)}")
    return parts


def dec(text: str) -> int:
    """A decimal integer with an optional leading '-' (syntax only)."""
    if not _DEC.match(text):
        raise CommandError(ErrorCode.SYNTAX, f"not a decimal integer: {text!r}")
    return int(text)


def plain(text: str) -> int | None:
    """``text`` as ASCII digits without a sign, else None: for the mutants that keep a
    refused value (``str.isdigit`` takes ``²``, which ``int`` then refuses)."""
    return int(text) if _DEC.match(text) and text[:1] != "-" else None


def hexa(text: str) -> int:
    """A hexadecimal field of one or more digits of either case (syntax only)."""
    if not _HEX.match(text):
        raise CommandError(ErrorCode.SYNTAX, f"not hexadecimal: {text!r}")
    return int(text, 16)


def decfloat(text: str) -> float:
    """``-?digits[.digits][e|E[+|-]digits]`` (the EFW value, spec 3)."""
    if not _FLOAT.match(text):
        raise CommandError(ErrorCode.SYNTAX, f"not a decimal number: {text!r}")
    return float(text)


def within(value: int, lo: int, hi: int) -> int:
    """``value`` if it lies in lo..hi, else error 5."""
    if not lo <= value <= hi:
        raise CommandError(ErrorCode.RANGE, f"{value} outside {lo}..{hi}")
    return value
