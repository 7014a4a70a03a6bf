"""Where the index (`@`, spec 8) is compared from in a sequence: each side's own first
reading of it. A fresh emulator starts at 0, but what a unit's first `@` answers is its
own (counting the `@` itself is a reading, spec 8 [D]; a real unit's index is not reset
between sequences), so the first `@` both sides answer sets the offset and later ones
are compared from there. A later difference that the queries sent since then account for
exactly (one more for each `@` and `>` the unit took) is that reading, not a miscount.
No manual gives the index's number format either: a target whose `@` reads as the
reference's once its text is read as hex, from a base read as hex too, writes it in hex
(8.index.decimal [D]), not a miscount. Nor do the manuals say whether a refused frame
counts ("zjistit, zda ho interpolátor přijal"): a target off the reference by exactly
the frames the reference refused since the base leaves them out (8.index.refused-counted
[D])."""

from __future__ import annotations

from dataclasses import dataclass

from conformance.protocol import index
from conformance.protocol.catalogue import classes

#: what a query of the index is (what the index leaves out); a unit may count these
#: (spec 8 [D])
QUERIES = classes(indexed=False)
#: how a frame was sent that no unit counts (spec 8): see engine._context
UNCOUNTED = {"other-address", "stalled", "bad-checksum", "no-checksum"}


@dataclass
class IndexBase:
    """The target's index minus the reference's where the sequence first read both
    (None until then) and the queries taken since."""

    offset: int | None = None
    queries: int = 0
    #: the offset with the target's index read as hex (None: not read so, or not yet)
    hex_offset: int | None = None
    #: the frames the reference refused (an error code) since the base
    refused: int = 0

    @classmethod
    def read(cls, target: list[str], reference: int) -> IndexBase:
        """The base from the index each side read before the sequence: the target's as it
        wrote it, in either form it may be read in (neither: no base yet)."""
        a, h = _number(target), _hex(target)
        return cls(offset=None if a is None else (a - reference) % 256,
                   hex_offset=None if h is None else (h - reference) % 256)

    def note(self, command: str, context: set[str], target: list[str],
             reference: list[str]) -> None:
        """Before a frame's answers are compared: a query taken counts from the base on;
        the first `@` both sides answer with a number sets the base."""
        if command not in QUERIES or context & UNCOUNTED:
            return
        if self.offset is not None or self.hex_offset is not None:
            self.queries += 1
            return
        a, b = _number(target), _number(reference)
        if command == "@" and b is not None:
            if a is not None:
                self.offset = (a - b) % 256
            h = _hex(target)
            if h is not None:
                self.hex_offset = (h - b) % 256

    def counts_queries(self, target: list[str], reference: list[str]) -> bool:
        """Whether the target's `@` is off the reference's by the queries since the base
        exactly: the unit counts `@` and `>` as it counts every other frame."""
        a, b = _number(target), _number(reference)
        return (self.offset is not None and a is not None and b is not None
                and self.queries % 256 != 0
                and (a - b - self.offset) % 256 == self.queries % 256)


    def refused_frame(self, command: str, context: set[str]) -> None:
        """A frame the reference refused: one more a unit may leave out of the index."""
        based = self.offset is not None or self.hex_offset is not None
        if based and command not in QUERIES and not context & UNCOUNTED:
            self.refused += 1

    def skips_refused(self, target: list[str], reference: list[str]) -> bool:
        """Whether the target's `@` is off the reference's by the frames the reference
        refused since the base exactly, the index read in either form."""
        b = _number(reference)
        if b is None or self.refused % 256 == 0:
            return False
        return any(a is not None and base is not None
                   and (b + base - a) % 256 == self.refused % 256
                   for a, base in ((_number(target), self.offset),
                                   (_hex(target), self.hex_offset)))

    def in_hex(self, target: list[str], reference: list[str]) -> bool:
        """Whether the target's `@` differs from the reference's only by being written in
        hex: read as hex, from the base read as hex (0 before any), it is the
        reference's."""
        a, b = _hex(target), _number(reference)
        return (a is not None and b is not None and target != reference
                and (a - (self.hex_offset or 0)) % 256 == b % 256)


def _hex(values: list[str]) -> int | None:
    return index.value(values[0], index.Form.HEX) if len(values) == 1 else None


def _number(values: list[str]) -> int | None:
    if len(values) != 1:
        return None
    try:
        return int(values[0])
    except ValueError:
        return None
