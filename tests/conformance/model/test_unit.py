"""Unit tests of the suite's own abstract unit model; expectations come from the spec."""

from __future__ import annotations

import pytest

from conformance.model.unit import ModelUnit
from conformance.protocol.view import View, observe
from conformance.protocol.wire import parse_response


class Wire:
    """The unit's view from the wire, as a machine's link feeds it."""

    def __init__(self, view: View | None = None) -> None:
        self.view = view or View()

    def sent(self, body: str, answer: bytes | None = None) -> None:
        r = None if answer is None else parse_response(answer, summed=False)
        self.view = observe(self.view, body, r)


def packet_unit() -> tuple[ModelUnit, Wire]:
    """A model whose unit was sent `*S` (unanswered: a packet is open)."""
    wire = Wire()
    unit = ModelUnit(wire=lambda: wire.view)
    wire.sent("*S")
    unit.open_packet()
    return unit, wire


def test_index_counts_every_verified_frame_but_at_and_repeat() -> None:
    unit = ModelUnit()
    for name in ("A", "*S", "C", "*E", "L", "@", ">"):  # spec 8: members, *S, *E counted
        unit.frame_arrived(name)
    assert unit.index == 5


def test_frames_failing_their_checksum_do_not_count() -> None:
    unit = ModelUnit(wire=lambda: View(checksums=True))
    unit.frame_arrived("A", checksum_ok=False)
    assert unit.index == 0


def test_index_wraps_modulo_256() -> None:
    unit = ModelUnit()
    for _ in range(257):
        unit.frame_arrived("A")
    assert unit.index == 1


@pytest.mark.parametrize(
    ("checksums", "sum_state", "code"),
    [
        (True, "good", 0),
        (True, "bad", 4),      # spec 6: wrong checksum -> 4
        (True, "missing", 4),  # spec 6: missing checksum -> 4
        (False, "missing", 0),  # checksums off after reset: plain frames execute
    ],
)
def test_checksum_answers(checksums: bool, sum_state: str, code: int) -> None:
    unit = ModelUnit(wire=lambda: View(checksums=checksums))
    assert unit.checksum_answer(sum_state) == code


def test_end_without_open_packet_is_4_0() -> None:
    assert ModelUnit().end_packet(0, room=64) == (4, 0)  # spec 7


def test_packet_count_mismatch_is_2_with_received_count() -> None:
    unit, wire = packet_unit()
    unit.member("C", 0)
    assert unit.end_packet(2, room=64) == (2, 1)
    wire.sent("*E2", b"2,1\r")
    assert unit.packet is None


def test_the_mode_and_the_open_packet_are_the_wire_s() -> None:
    """Decided (docs/decisions.md, "one view of the unit"): the model keeps no mode or
    packet of its own; an answered `*S` opens none, a frame answered in one ends it."""
    wire = Wire()
    unit = ModelUnit(wire=lambda: wire.view)
    wire.sent("%+", b"0\r")
    assert unit.checksums
    wire.sent("*S", b"4\r")
    assert unit.packet is None
    wire.sent("*S")
    unit.member("C", 0)
    assert unit.packet == [("C", 0)]
    wire.sent("V100", b"0\r")
    assert unit.packet is None and unit.end_packet(1, room=64) == (4, 0)


def test_packet_first_failing_member_code_wins() -> None:
    unit, _ = packet_unit()
    unit.member("C", 0)
    unit.member("B", 3)
    unit.member("C", 4)
    assert unit.end_packet(3, room=64) == (3, 3)


def test_packet_without_room_for_its_vectors_is_1() -> None:
    unit, _ = packet_unit()
    unit.member("C", 0)
    unit.member("C", 0)
    unit.member("B", 0)  # B members take no queue room
    assert unit.end_packet(3, room=1) == (1, 3)
    unit.open_packet()
    for kind in ("C", "C", "B"):
        unit.member(kind, 0)
    assert unit.end_packet(3, room=2) == (0, 3)


def test_booking_adds_commanded_steps_per_axis() -> None:
    unit = ModelUnit()
    unit.book((10, -5, 0))
    unit.book((1, 2, 3))
    assert unit.committed == [11, -3, 3]
