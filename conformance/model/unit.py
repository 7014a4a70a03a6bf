"""An abstract GVE unit: the protocol state a host can observe (spec 4-8, 10.1, 10.5).

It does not simulate motion; it books what the unit must have accepted, so that the
machines can check the index, the checksum mode, packets and position bookkeeping.

The checksum mode and whether a packet is open are not the model's: they are the one
view of the unit from the wire (conformance/protocol/view.py) that the machine's link
feeds with every frame it sends. The model keeps what it expects: the index by its
counting rules, the codes the open packet's members must fail it with, the motion
committed.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from conformance.protocol.catalogue import classes
from conformance.protocol.view import View
from gve_fixtures.protocol import ErrorCode

UNCOUNTED = tuple(sorted(classes(indexed=False)))       # spec 8
PACKET_MEMBERS = classes(packet="member")               # spec 7


@dataclass
class ModelUnit:
    axes: int = 3
    buffer: int = 64
    #: the unit as the wire shows it now (a machine's: its link's view)
    wire: Callable[[], View] = View
    index: int = 0
    inta: bool = False
    #: the open packet's members as expected: (member kind, the code it fails it with)
    members: list[tuple[str, ErrorCode]] = field(default_factory=list)
    committed: list[int] = field(default_factory=lambda: [0, 0, 0])
    #: frames that do not advance the index: @ and > by our reading [D]; a unit whose @
    #: counts itself (measured by the machines) has none
    uncounted: tuple[str, ...] = UNCOUNTED
    #: whether a refused frame advances the index, as we read it [D]; a unit that counts
    #: only what it takes (measured by the machines) does not
    refused_counted: bool = True

    @property
    def checksums(self) -> bool:
        """The checksum mode, as the wire shows it (spec 6)."""
        return self.wire().checksums

    @property
    def packet(self) -> list[tuple[str, ErrorCode]] | None:
        """The open packet's expected members (None: none open, as the wire shows)."""
        return self.members if self.wire().packet_open else None

    # -- section 8 ------------------------------------------------------------------------
    def frame_arrived(self, name: str, checksum_ok: bool = True,
                      code: int | None = None) -> None:
        """A complete frame for the unit arrived (spec 8: counted unless @/> or a bad sum);
        ``code``: the error code it was answered with (None: no answer read)."""
        if code is not None and code & 7 and not self.refused_counted:   # (8: INTA, taken)
            return
        if checksum_ok and name not in self.uncounted:
            self.index = (self.index + 1) % 256

    # -- section 6 ------------------------------------------------------------------------
    def checksum_answer(self, sum_state: str) -> ErrorCode:
        """The code for a frame whose checksum is "good", "bad", "missing" or "lower"."""
        if not self.checksums:
            return ErrorCode.OK if sum_state == "missing" else ErrorCode.SYNTAX
        return ErrorCode.OK if sum_state in ("good", "lower") else ErrorCode.SYNTAX

    # -- section 7 ------------------------------------------------------------------------
    def open_packet(self) -> None:
        """An `*S` went: the packet it opens (on the wire) expects no member yet."""
        self.members = []

    def member(self, kind: str, code: ErrorCode) -> None:
        self.members.append((kind, code))

    def end_packet(self, n: int, room: int) -> tuple[ErrorCode, int]:
        """(code, k) of *E<n> (spec 7), and commit when OK."""
        if self.packet is None:
            return ErrorCode.SYNTAX, 0
        members, self.members = self.members, []
        k = len(members)
        if k != n:
            return ErrorCode.COUNT_MISMATCH, k
        for _, c in members:
            if c:
                return c, k
        vectors = sum(1 for kind, _ in members if kind == "C")
        if vectors > room:
            return ErrorCode.QUEUE_FULL, k
        return ErrorCode.OK, k

    def book(self, steps: tuple[int, ...]) -> None:
        for i, s in enumerate(steps):
            self.committed[i] += s
