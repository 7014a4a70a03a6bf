"""Where the index (`@`, spec 8) is compared from in a sequence: each side's own first
reading of it. A fresh emulator starts at 0, but what a unit's first `@` answers is its
own (counting the `@` itself is a reading, spec 8 [D]; a real unit's index is not reset
between sequences), so the first `@` both sides answer sets the offset and later ones
are compared from there. A later difference that the queries sent since then account for
exactly (one more for each `@` and `>` the unit took) is that reading, not a miscount."""

from __future__ import annotations

from dataclasses import dataclass

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
        if command == "@" and a is not None and b is not None:
            self.offset = (a - b) % 256

    def counts_queries(self, target: list[str], reference: list[str]) -> bool:
        """Whether the target's `@` is off the reference's by the queries since the base
        exactly: the unit counts `@` and `>` as it counts every other frame."""
        a, b = _number(target), _number(reference)
        return (self.offset is not None and a is not None and b is not None
                and self.queries % 256 != 0
                and (a - b - self.offset) % 256 == self.queries % 256)


def _number(values: list[str]) -> int | None:
    if len(values) != 1:
        return None
    try:
        return int(values[0])
    except ValueError:
        return None
