"""A frame's body read as the catalogue's commands: which command, which fields.

One reading for every reader of the suite, so that the guard, diff and the host role
never class one frame two ways. Two modes:

- lenient (the default) reads the body as a unit that does not conform might: letters
  of either case, ``+6`` or `` 6`` for 6. It is how a frame is *classed*: the guard must
  judge what a frame could do, and diff and the host role class it the same way.
- strict reads it as spec 3 writes it: upper-case command letters only; whether the
  fields are well formed is left to the judge of the host role (host/frame_rules.py).

A frame whose command is ``SW`` and whose first field reads 6 writes ST6 and is classed
``SW6`` (spec 10.3: writing ST6 can stop or resume motion).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

from conformance.protocol.bounded import decimal, hexadecimal
from conformance.protocol.catalogue import ST6_WRITE, catalogue, names_longest_first

_ST6 = 6
_ADDRESSES = frozenset("01234567")


@dataclass(frozen=True)
class Parsed:
    """A body as read: ``name`` the catalogue's wire name (None: no command of spec 10),
    ``params`` the text after it, ``fields`` the parameters (a glued first field on its
    own, then the comma-separated rest)."""

    address: int | None
    name: str | None
    params: str
    fields: tuple[str, ...]
    writes_st6: bool = False

    @property
    def key(self) -> str:
        """The frame's class: the command's name, ``SW6`` for a write of ST6, "" for no
        command of spec 10."""
        if self.writes_st6:
            return ST6_WRITE
        return self.name or ""


@lru_cache(maxsize=4096)     # every reader parses each frame; Parsed is immutable
def parse(body: str, *, strict: bool = False, address: int | None = None) -> Parsed:
    """Read ``body`` (the frame from the byte after its address, without the checksum)."""
    text = body if strict else body.upper()
    name = _name(text)
    if name is None:
        return Parsed(address, None, text, ())
    params = text[len(name):]
    split = split_fields(name, params)
    writes = name == "SW" and bool(split) and read_int(split[0], strict=strict) == _ST6
    return Parsed(address, name, params, split, writes)


def parse_text(text: str, *, strict: bool = False) -> Parsed:
    """Read a frame's text after `!` (its address digit, then the body)."""
    digit = text[:1]
    address = int(digit) if digit in _ADDRESSES else None
    return parse(text[1:] if address is not None else text, strict=strict, address=address)


def _name(text: str) -> str | None:
    for name in names_longest_first():
        if text.startswith(name):
            return name
    return None


def split_fields(name: str, params: str) -> tuple[str, ...]:
    """The parameters of ``name`` in ``params``: a glued first field is one character
    right after the command letters, its comma optional (`WY,-20000,...`, `M4`)."""
    parts: list[str] = []
    text = params
    if catalogue()[name].glued:
        parts, text = [text[:1]], text[1:]
        if text.startswith(","):
            text = text[1:]
        if not text:
            return tuple(p for p in parts if p)
    return (*parts, *text.split(",")) if text else tuple(parts)


def read_int(text: str, *, strict: bool = False, base: int = 10) -> int | None:
    """A field's integer (ASCII digits, bounded: protocol/bounded.py); lenient: spaces and
    a leading `+` as a unit that does not conform might take them. None: not an
    integer."""
    if not strict:
        text = text.strip().lstrip("+")
    if base == 16:
        return hexadecimal(text)
    return decimal(text, signed=True)
