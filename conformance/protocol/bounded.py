"""Numbers and JSON from a target, read with bounds: the one reader of every text a unit,
a simulator, its rig or a host program sends where the suite needs a value.

Python's own readers take more than any protocol here allows: ``str.isdigit()`` and
``int()`` accept ``²`` and other scripts' digits, ``int()`` also ``1_000`` and spaces, and
raises (not returns) past 4300 digits; ``json.loads`` recurses once per nested array and
ends in RecursionError. Here a number is ASCII digits only, at most :data:`DIGITS` of them,
and JSON has a length and a depth limit. Whatever does not fit is not a value: the readers
return None (numbers) or raise :class:`Unreadable` (JSON, saying why), never anything a
caller would take for a defect of the suite or a mistake on the command line.
"""

from __future__ import annotations

import json
import re
from typing import Any

#: the most digits a number from a target may have: 2**64 has 20 (a virtual instant in
#: nanoseconds, a position, a count: every number of these protocols fits)
DIGITS = 20
#: the longest JSON text read (a rig's `state` is a few hundred characters)
JSON_CHARS = 1 << 16
#: the deepest nesting of arrays and objects read (a rig's `state` nests three deep)
JSON_DEPTH = 16

_DECIMAL = re.compile(rf"[0-9]{{1,{DIGITS}}}")
_SIGNED = re.compile(rf"-?[0-9]{{1,{DIGITS}}}")
_HEX = re.compile(rf"[0-9A-Fa-f]{{1,{DIGITS}}}")
#: a JSON string (skipped when counting the nesting) or one bracket
_NESTING = re.compile(r'"(?:[^"\\]|\\.)*"|[\[\]{}]')


class Unreadable(Exception):
    """Text from a target that is not what the suite reads there (not a ValueError: a
    command-line interface takes those for the user's mistakes)."""


def decimal(text: str, *, signed: bool = False) -> int | None:
    """``text`` as a decimal number of ASCII digits (``-`` first when ``signed``); None
    when it is not one or has more than DIGITS digits."""
    return int(text) if (_SIGNED if signed else _DECIMAL).fullmatch(text) else None


def hexadecimal(text: str) -> int | None:
    """``text`` as a hexadecimal number of ASCII digits, either case; None when it is
    not one or has more than DIGITS digits."""
    return int(text, 16) if _HEX.fullmatch(text) else None


def depth(text: str) -> int:
    """How deeply the arrays and objects of a JSON text nest (brackets inside strings
    not counted); read without recursion, whatever the text."""
    deepest = level = 0
    for m in _NESTING.finditer(text):
        token = m.group(0)
        if token in "[{":
            level += 1
            deepest = max(deepest, level)
        elif token in "]}":
            level -= 1
    return deepest


def _no_constant(name: str) -> Any:
    raise ValueError(f"{name} is not JSON")


def json_value(text: str) -> Any:
    """One JSON value, at most JSON_CHARS long and JSON_DEPTH deep (no NaN, no Infinity,
    no number of more than 4300 digits); Unreadable saying why otherwise."""
    if len(text) > JSON_CHARS:
        raise Unreadable(f"{len(text)} characters of JSON, more than {JSON_CHARS}")
    # no deeper than its opening brackets, counted at C speed (a rig's `state` has a
    # dozen): the walk that skips those inside strings only where there are more
    if text.count("[") + text.count("{") > JSON_DEPTH and depth(text) > JSON_DEPTH:
        raise Unreadable(f"JSON nested more than {JSON_DEPTH} deep")
    try:
        return json.loads(text, parse_constant=_no_constant)
    except (ValueError, RecursionError) as err:
        raise Unreadable(f"not JSON: {str(err)[:120]}") from None


def json_object(text: str | None) -> dict | None:
    """``text`` as one JSON object within the bounds of :func:`json_value` (None: it is
    not one)."""
    if not text:
        return None
    try:
        value = json_value(text)
    except Unreadable:
        return None
    return value if isinstance(value, dict) else None
