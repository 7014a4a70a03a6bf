"""Unit tests of the suite's own abstract unit model; expectations come from the spec."""

from __future__ import annotations

import pytest

from conformance.model.unit import ModelUnit


def test_index_counts_every_verified_frame_but_at_and_repeat() -> None:
    unit = ModelUnit()
    for name in ("A", "*S", "C", "*E", "L", "@", ">"):  # spec 8: members, *S, *E counted
        unit.frame_arrived(name)
    assert unit.index == 5


def test_frames_failing_their_checksum_do_not_count() -> None:
    unit = ModelUnit(checksums=True)
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
    assert ModelUnit(checksums=checksums).checksum_answer(sum_state) == code


def test_end_without_open_packet_is_4_0() -> None:
    assert ModelUnit().end_packet(0, room=64) == (4, 0)  # spec 7


def test_packet_count_mismatch_is_2_with_received_count() -> None:
    unit = ModelUnit()
    unit.open_packet()
    unit.member("C", 0)
    assert unit.end_packet(2, room=64) == (2, 1)
    assert unit.packet is None


def test_packet_first_failing_member_code_wins() -> None:
    unit = ModelUnit()
    unit.open_packet()
    unit.member("C", 0)
    unit.member("B", 3)
    unit.member("C", 4)
    assert unit.end_packet(3, room=64) == (3, 3)


def test_packet_without_room_for_its_vectors_is_1() -> None:
    unit = ModelUnit()
    unit.open_packet()
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
