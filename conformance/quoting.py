"""One way to show what a check observed and expected, the same on the console, in the
HTML report and in JUnit: the bytes a unit sent as transcripts write them (printable
ASCII as itself, ``\\r`` and ``\\xNN`` for the rest: ``F\\r``), in double quotes, never a
Python ``repr`` (which doubled the backslashes and showed ``b'...'``). An answer the
suite read (a :class:`Response`) is written as the spec writes answers, without the CR
that ends it (``8,D0``), as every check's expected answer is."""

from __future__ import annotations

from typing import Any

from conformance.link.framing import Response, readable

#: what an empty observation is shown as
NOTHING = "(nothing)"


def as_text(value: Any) -> str:
    """A check's value as it is kept in a result: bytes as a transcript writes them,
    None as empty, anything else as its text."""
    if value is None:
        return ""
    if isinstance(value, Response):
        return answer_text(value.raw)
    if isinstance(value, bytes | bytearray):
        return readable(bytes(value))
    return str(value)


def quoted(text: str) -> str:
    """``"F\\r"``; ``(nothing)`` for an empty text."""
    return f'"{text}"' if text else NOTHING


def answer_text(raw: bytes) -> str:
    """An answer as checks write it: ``8,D0`` for ``8,D0\\r``; an answer that does not
    end in CR says so."""
    if raw.endswith(b"\r"):
        return readable(raw[:-1])
    return f"{readable(raw)} (no CR at its end)" if raw else ""
