"""One way to show what a target sent — a unit, a simulator (its lines, its standard
error), a host program — the same on the console, in the text reports, in the HTML
report and in JUnit: the bytes as transcripts write them (printable ASCII as itself,
``\\r``, ``\\n`` and ``\\xNN`` for the rest: ``F\\r``), a program's text with every
character that is not printable escaped alike, in double quotes, never a Python
``repr`` (which doubled the backslashes and showed ``b'...'``). Nothing a target sends
reaches a terminal raw: no escape sequence, no carriage return, no line of its own. An
answer the suite read (a :class:`Response`) is written as the spec writes answers,
without the CR that ends it (``8,D0``), as every check's expected answer is."""

from __future__ import annotations

from typing import Any

from conformance.link.framing import Response, readable, shown_bytes

#: what an empty observation is shown as
NOTHING = "(nothing)"
#: the most characters of a target's text one message shows (then "...")
SHOWN_CHARS = 200

_NAMED = {"\r": "\\r", "\n": "\\n", "\t": "\\t", "\\": "\\\\"}


def as_text(value: Any) -> str:
    """A check's value as it is kept in a result: bytes as a transcript writes them,
    None as empty, anything else as its text with every character that is not printable
    escaped (a unit's text kept as a str, a pattern's backslashes left as written)."""
    if value is None:
        return ""
    if isinstance(value, Response):
        return answer_text(value.raw)
    if isinstance(value, bytes | bytearray):
        return readable(bytes(value))
    text = str(value)
    if text.isprintable():
        return text
    return "".join(ch if ch.isprintable() else _character(ch) for ch in text)


def quoted(text: str) -> str:
    """``"F\\r"``; ``(nothing)`` for an empty text."""
    return f'"{text}"' if text else NOTHING


def answer_text(raw: bytes) -> str:
    """An answer as checks write it: ``8,D0`` for ``8,D0\\r``; an answer that does not
    end in CR says so."""
    if raw.endswith(b"\r"):
        return readable(raw[:-1])
    return f"{readable(raw)} (no CR at its end)" if raw else ""


def _character(ch: str) -> str:
    if ch in _NAMED:
        return _NAMED[ch]
    if ch.isprintable():
        return ch
    code = ord(ch)
    return f"\\x{code:02X}" if code < 0x100 else f"\\u{code:04X}" if code < 0x10000 \
        else f"\\U{code:08X}"


def escaped(value: str | bytes | bytearray) -> str:
    """What a target sent, escaped for people, without quotes: bytes as a transcript
    writes them; text with CR, LF, TAB and the backslash named and every character that
    is not printable (controls, escape sequences, invisible formatting) as ``\\xNN``."""
    if isinstance(value, bytes | bytearray):
        return readable(bytes(value))
    return "".join(_character(ch) for ch in value)


def shown(value: str | bytes | bytearray, limit: int = SHOWN_CHARS) -> str:
    """What a target sent, for a message: its first ``limit`` characters (or bytes)
    escaped, in double quotes, ``...`` when there was more; ``(nothing)`` when empty."""
    if isinstance(value, bytes | bytearray):
        return shown_bytes(bytes(value), limit) if value else NOTHING
    text = escaped(value[:limit])
    return quoted(text + "..." if len(value) > limit else text)
