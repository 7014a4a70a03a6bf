"""The numbers of the text channels (the rig's, docs/rig.md; co-simulation's,
docs/cosim.md), read with bounds: ASCII digits only (``str.isdigit`` takes ``²`` and
other digits ``int`` refuses), a bounded length, and a ValueError that says what was
expected rather than what ``int`` thought."""

from __future__ import annotations

import string

#: digits a decimal word may have: an instant of the clock's range (2^61 ns) has 19
DECIMAL_DIGITS = 20
_DECIMAL = frozenset(string.digits)
_HEX = frozenset(string.hexdigits)


def decimal(text: str, what: str, *, signed: bool = False) -> int:
    """``text`` as a whole number (a sign only when ``signed``)."""
    digits = text[1:] if signed and text[:1] in ("-", "+") else text
    if not digits or len(digits) > DECIMAL_DIGITS or not set(digits) <= _DECIMAL:
        form = "a sign and digits" if signed else "digits"
        raise ValueError(f"{what} takes {form} 0-9 (at most {DECIMAL_DIGITS}), "
                         f"not {text[:40]!r}")
    return int(text)


def hex_byte(text: str, what: str) -> int:
    """``text`` as one byte in two hex digits."""
    if len(text) != 2 or not set(text) <= _HEX:
        raise ValueError(f"{what} is two hex digits (00..FF), not {text[:40]!r}")
    return int(text, 16)
