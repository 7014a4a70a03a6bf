"""Reading the unit's index (`@`, spec 8) in the form the unit writes it: the first read
whose text does not show its form measures the form first (frames that count move the
index: protocol/index.py), so the value returned is read after them."""

from __future__ import annotations

from collections.abc import Callable

from conformance.protocol import index
from conformance.protocol.index import Form
from conformance.protocol.wire import Response, UnitDataError, shown_bytes

Send = Callable[[str], Response | None]


def read_index(send: Send, form: Form | None) -> tuple[int | None, Form | None]:
    """The index `@` answers through ``send`` (None: no answer, or a refusal) and the form
    the unit writes it in (``form`` when known already, else read or measured). Raises
    UnitDataError for text no form reads."""
    r = send("@")
    if r is None or not r.ok or not r.values:
        return None, form
    if form is None:
        form = index.evident(r.values[0])
        if form is None:
            form = index.measure(lambda: _text(send), lambda: send("SR6"))  # SR6 moves the
            r = send("@")                                                  # index alone
            if r is None or not r.ok or not r.values:
                return None, None           # the form is not kept: the index unread
    return index_value(r, form), form


def index_value(r: Response, form: Form | None) -> int:
    """Value 0 of ``r`` (an answer to `@`) as the index, in ``form`` (decimal before it is
    known)."""
    text = r.values[0]
    got = index.value(text, form or Form.DECIMAL)
    if got is None:
        raise UnitDataError(f"the answer {shown_bytes(r.raw)} has "
                            f"{shown_bytes(text.encode('latin-1'), 80)} where the "
                            f"index belongs (a number 0..255, decimal or hex)")
    return got


def _text(send: Send) -> str | None:
    r = send("@")
    return r.values[0] if r is not None and r.ok and r.values else None
