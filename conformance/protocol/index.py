"""The index `@` answers, read in every form a reader of the manuals could write it.

No manual fixes how `@` writes "the index of the last command … modulo 256": decimal is
ours (8.index.decimal [D]); two hex digits, as the manuals write every other byte, is as
fair a reading, padded or not, either case. So the suite reads the index in the form the
unit writes it and grades the form once, by its own rule, in its own case: a check that
the index moved reads it in the unit's form, and only text no form can read (not a number
0..255 in either base) is the unit's fault everywhere.

The form shows itself in the text only where the bases differ: a hex letter is hex, a
number of three decimal digits above 255 is decimal; anything else (``"9"``, ``"10"``) is
read alike or ambiguously. An ambiguous text is settled by :func:`measure`: frames that
count move the index until a text shows its form (a hex index shows a letter within 10
moves; a decimal one never does).
"""

from __future__ import annotations

import re
from collections.abc import Callable
from enum import Enum

from conformance.protocol.bounded import decimal, hexadecimal

#: how many index moves settle an ambiguous form: a hex index moving by one or two a
#: frame shows a letter within 10 of them; a decimal one shows none however far it goes
MOVES = 10
_HEX_LETTER = re.compile(r"[A-Fa-f]")


class Form(Enum):
    DECIMAL = "decimal"
    HEX = "hex"


def value(text: str, form: Form) -> int | None:
    """``text`` as an index in ``form`` (None: not an index 0..255 in that form)."""
    if len(text) > 3:
        return None
    number = decimal(text) if form is Form.DECIMAL else hexadecimal(text)
    return number if number is not None and number < 256 else None


def readable(text: str) -> bool:
    """Whether any form reads ``text`` as an index (else: bytes no reading can parse)."""
    return any(value(text, form) is not None for form in Form)


def evident(text: str) -> Form | None:
    """The form ``text`` shows by itself: None where the forms read it alike (``"7"``) or
    both read it otherwise (``"10"``), or none reads it."""
    forms = [form for form in Form if value(text, form) is not None]
    if len(forms) == 1:
        return forms[0]
    return None


def ambiguous(text: str) -> bool:
    """Whether the forms read ``text`` as different indexes."""
    return len({value(text, form) for form in Form} - {None}) > 1


def measure(read: Callable[[], str | None], move: Callable[[], None]) -> Form:
    """The unit's form: ``read`` gives the text `@` answers (None: none), ``move`` sends
    one frame that counts. Decimal where no text shows hex within :data:`MOVES` moves of
    the index (the suite's form, which is then read alike)."""
    seen: set[str] = set()
    for _ in range(MOVES * 2):
        text = read()
        if text is None:
            break
        form = evident(text)
        if form is not None or _HEX_LETTER.search(text):
            return form or Form.HEX
        seen.add(text)
        if len(seen) > MOVES:
            break
        move()
    return Form.DECIMAL
