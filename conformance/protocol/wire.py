"""The suite's own framing of the wire (spec 3, 4, 6), written from the spec, not from the
emulator.

A frame is ``"!" address body ["," checksum] CR``; a response is
``code *("," value) ["," checksum] CR`` where the code's bit 3 is INTA.

Unit bytes are read through :class:`Response`, whose accessors (``hex``, ``dec``,
``decs``, indexing ``values``) raise :class:`UnitDataError` when the bytes are not what
the protocol allows there: the runner turns that into a failed check showing the bytes,
so a unit can never make the suite report ERROR.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from conformance.protocol.bounded import decimal
from gve_fixtures.protocol import INTA_BIT, ErrorCode, St6
from gve_fixtures.transcript import escape

CR = b"\r"
BANG = b"!"

#: a byte as the unit writes it: two upper-case hex digits (spec 4, 6)
HEX_BYTE = "[0-9A-F]{2}"
_HEX_BYTE = re.compile(HEX_BYTE)


def is_hex_byte(text: str, either_case: bool = False) -> bool:
    """Whether ``text`` is two hex digits (upper case, or of ``either_case``)."""
    return _HEX_BYTE.fullmatch(text.upper() if either_case else text) is not None


def readable(data: bytes) -> str:
    """Bytes as text for people: printable ASCII as itself, the rest escaped as in
    transcripts (``\\r``, ``\\x00``), so no raw control byte reaches a report (the one
    way every room shows them: conformance/verdicts/quoting.py)."""
    return bytes(data).decode("latin-1").translate(_READABLE)


#: each byte as :func:`readable` shows it, by its value (a table str.translate reads)
_READABLE = [chr(b) if 0x20 <= b <= 0x7E and b != 0x5C else escape(bytes([b]))
             for b in range(256)]


def shown_bytes(data: bytes, limit: int = 200) -> str:
    """A unit's bytes in a message: their first ``limit`` escaped, in double quotes,
    ``...`` when there were more (what conformance/verdicts/quoting.py's ``shown`` gives bytes)."""
    return f'"{readable(data[:limit])}{"..." if len(data) > limit else ""}"'


def byte_sum(data: bytes) -> int:
    """The checksum of spec 6: the sum of the bytes mod 256."""
    return sum(data) % 256


def frame(body: str, address: int = 0, checksum: bool | str = False) -> bytes:
    """The bytes of a command frame. ``checksum``: False (none), True (the right one),
    or literal text (a deliberately wrong or malformed one)."""
    head = f"!{address}{body}".encode("latin-1")
    if checksum is False:
        return head + CR
    if checksum is True:
        summed = head + b","
        return summed + b"%02X" % byte_sum(summed) + CR
    return head + b"," + str(checksum).encode("latin-1") + CR


class UnitDataError(AssertionError):
    """Unit bytes that are not what the protocol allows where the suite reads them.

    An AssertionError, so that a Hypothesis machine reports it as a failed invariant;
    the runner records it as a failed check (always FAIL) with the bytes."""


class Values(list):
    """A response's values: indexing past the end is the unit's fault, not the suite's."""

    def __init__(self, items: list[str], raw: bytes) -> None:
        super().__init__(items)
        self.raw = raw

    def __getitem__(self, index):
        try:
            return super().__getitem__(index)
        except IndexError:
            raise UnitDataError(f"the answer {shown_bytes(self.raw)} has no value "
                                f"{index}") from None


@dataclass
class Response:
    """One answer as the suite reads it."""

    raw: bytes
    lines: list[bytes] = field(default_factory=list)
    code: int | None = None
    inta: bool | None = None
    values: Values = field(default_factory=lambda: Values([], b""))
    checksum: str | None = None
    checksum_ok: bool | None = None
    well_formed: bool = False
    sent_at: int = 0
    received_at: int = 0

    @property
    def text(self) -> str:
        """The bytes as readable text: printable ASCII as itself, the rest escaped
        (``\\r``, ``\\x00``), so a report can never carry a raw control byte."""
        return readable(self.raw)

    def __str__(self) -> str:
        return self.text

    # -- safe accessors: the unit's fault when the bytes are not there ---------------------
    def _fail(self, what: str) -> UnitDataError:
        return UnitDataError(f"the answer {shown_bytes(self.raw)} {what}")

    def hex(self, index: int = 0) -> int:
        """Value ``index`` as two upper-case hex digits (status words, ports, EEPROM bytes)."""
        text = self.values[index]
        if not is_hex_byte(text):
            raise self._fail(f"has {_value(text)} where two hex digits belong")
        return int(text, 16)

    def dec(self, index: int = 0) -> int:
        """Value ``index`` as a decimal integer (positions, counts, the index)."""
        text = self.values[index]
        value = decimal(text, signed=True)
        if value is None:
            raise self._fail(f"has {_value(text)} where a decimal number belongs")
        return value

    def decs(self) -> list[int]:
        """Every value as a decimal integer."""
        return [self.dec(i) for i in range(len(self.values))]

    @property
    def error(self) -> ErrorCode | None:
        """The code as the protocol names it (None: no code could be read)."""
        return None if self.code is None else ErrorCode(self.code)

    @property
    def ok(self) -> bool:
        return self.code == ErrorCode.OK

    def st6(self, index: int = 0) -> St6:
        """Value ``index`` read as status word ST6 (the answer to `SR6` or `F`)."""
        return St6(self.hex(index))


def _value(text: str) -> str:
    """A value of an answer (the unit's bytes read as latin-1) shown as its bytes are."""
    return shown_bytes(text.encode("latin-1"), 80)


def parse_response(raw: bytes, *, summed: bool, lines: int = 1) -> Response:
    """Parse what arrived for one command (``lines`` CR-terminated lines; the last one is
    the response proper, as after `>`)."""
    parts = raw.split(CR)
    got = [p for p in parts[:-1]]
    r = Response(raw=raw, lines=got, values=Values([], raw))
    if len(got) != lines or parts[-1] != b"":
        return r
    last = got[-1]
    text = last.decode("latin-1")
    fields = text.split(",")
    head = fields[0]
    if len(head) != 1 or head not in "0123456789ABCDEF":
        return r
    value = int(head, 16)
    r.code, r.inta = value & 7, bool(value & INTA_BIT)
    values = fields[1:]
    if summed:
        if not values or len(values[-1]) != 2:
            r.checksum_ok = False
            r.values = Values(values, raw)
            return r
        r.checksum = values[-1]
        upto = last[: len(last) - 2]
        r.checksum_ok = r.checksum == "%02X" % byte_sum(upto)
        values = values[:-1]
    r.values = Values(values, raw)
    r.well_formed = all(v != "" for v in values) and (not summed or bool(r.checksum_ok))
    return r
