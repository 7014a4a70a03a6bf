"""A unit that ends a packet at any frame but `C` or `B` and answers that frame at once (a
reading of M114 13.4) gets each answer given to the frame it answered: the link never
takes a member's answer for `*E`'s, nor calls the answers that follow answers twice."""

from __future__ import annotations

import pytest

from conformance.link.link import Link
from conformance.link.safety import Guard
from conformance.protocol.parse import parse
from gve_fixtures.profile import load_profile


class _AbandoningUnit:
    """A real-time port on a unit that ends its packet at any frame but C or B and
    answers that frame `0` at once; `*E` without a packet answers 4. ``early``: its
    answers wait to be read before the next frame goes out (else they come only when
    the link reads)."""

    timeout = None

    def __init__(self, early: bool) -> None:
        self.early = early
        self.packet = False
        self.lines: list[bytes] = []

    @property
    def in_waiting(self) -> int:
        return sum(map(len, self.lines)) if self.early else 0

    def write(self, data: bytes) -> None:
        name = parse(data[2:-1].decode()).key
        if name == "*S":
            self.packet = True
        elif self.packet and name in ("C", "B"):
            pass
        elif name == "*E":
            self.lines.append(b"0,2\r" if self.packet else b"4\r")
            self.packet = False
        else:
            self.packet = False
            self.lines.append(b"0\r")

    def read_until(self, _end: bytes) -> bytes:
        return self.lines.pop(0) if self.lines else b""

    def read(self, n: int) -> bytes:
        out = b"".join(self.lines)[:n]
        self.lines = []
        return out


@pytest.mark.parametrize("early", [True, False], ids=["read-before-next", "read-with-next"])
def test_an_answer_after_a_member_is_that_members(early):
    guard = Guard(load_profile("GVE84-100"), 0, max_travel=1000, allow_destructive=True)
    link = Link(_AbandoningUnit(early), guard, virtual=False)
    link.send("*S", answer=False)
    for member in ("C10,0,0", "V100", "C10,0,0"):
        link.send(member, answer=False)
    r = link.send("*E3")
    assert r is not None and r.raw == b"4\r"          # no packet was open any more
    assert link.violations == []
    assert not link.view.packet_open and link.view.pending == ()
    assert link.send("H").raw == b"0\r"               # nothing piled up
    notes = [rec.line() for rec in link.log if rec.data == b"0\r" and "sent before" in
             rec.line()]
    assert len(notes) == 2 and "V100" in notes[0] and "C10,0,0" in notes[1]
