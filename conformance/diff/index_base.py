"""Where the index (`@`, spec 8) is compared from in a sequence: each side's own first
reading of it. A fresh emulator starts at 0, but what a unit's first `@` answers is its
own (counting the `@` itself is a reading, spec 8 [D]; a real unit's index is not reset
between sequences), so the first `@` both sides answer sets the offset and later ones
are compared from there. A later difference that the queries sent since then account for
exactly (one more for each `@` and `>` the unit took) is that reading, not a miscount.
No manual gives the index's number format either: a target whose `@` reads as the
reference's once its text is read as hex, from a base read as hex too, writes it in hex
(8.index.decimal [D]), not a miscount."""

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
    #: the frames both sides refused since the base (counted by our reading [D])
    refused: int = 0

    def note(self, command: str, context: set[str], target: list[str],
             reference: list[str]) -> None:
        """Before a frame's answers are compared: a query taken counts from the base on;
        the first `@` both sides answer with a number sets the base."""
        if command not in QUERIES or context & UNCOUNTED:
            return
        if self.offset is not None:
            self.queries += 1
            return
        a, b = _number(target), _number(reference)
        if command == "@" and b is not None:
            if a is not None:
                self.offset = (a - b) % 256
            h = _hex(target)
            if h is not None:
                self.hex_offset = (h - b) % 256

    def refused_frame(self, command: str, context: set[str]) -> None:
        """A counted frame both sides refused (an error code), after the base was set."""
        if self.offset is not None and command not in QUERIES and not context & UNCOUNTED:
            self.refused += 1

    def skips_refused(self, target: list[str], reference: list[str]) -> bool:
        """Whether the target's `@` is short of the reference's by the frames refused
        since the base exactly (the queries since counted or not): a unit that counts
        what it took, not a miscount (8.index.refused-counted [D])."""
        a, b = _number(target), _number(reference)
        if self.offset is None or a is None or b is None or self.refused % 256 == 0:
            return False
        return (a - b - self.offset) % 256 in {(-self.refused) % 256,
                                                (self.queries - self.refused) % 256}

    def counts_queries(self, target: list[str], reference: list[str]) -> bool:
        """Whether the target's `@` is off the reference's by the queries since the base
        exactly: the unit counts `@` and `>` as it counts every other frame."""
        a, b = _number(target), _number(reference)
        return (self.offset is not None and a is not None and b is not None
                and self.queries % 256 != 0
                and (a - b - self.offset) % 256 == self.queries % 256)

    def in_hex(self, target: list[str], reference: list[str]) -> bool:
        """Whether the target's `@` differs from the reference's only by being written in
        hex: read as hex, from the base read as hex (0 before any), it is the
        reference's."""
        a, b = _hex(target), _number(reference)
        return (a is not None and b is not None and target != reference
                and (a - (self.hex_offset or 0)) % 256 == b % 256)

    def context(self, target: list[str], reference: list[str]) -> set[str]:
        """The labels' context flags of two `@` answers that differ: the readings of the
        index they are (queries counted, refused frames not, written in hex)."""
        flags = {"queries-counted": self.counts_queries(target, reference),
                 "refused-uncounted": self.skips_refused(target, reference),
                 "index-hex": self.in_hex(target, reference)}
        return {flag for flag, on in flags.items() if on}


def _hex(values: list[str]) -> int | None:
    return index.value(values[0], index.Form.HEX) if len(values) == 1 else None


def _number(values: list[str]) -> int | None:
    if len(values) != 1:
        return None
    try:
        return int(values[0])
    except ValueError:
        return None
