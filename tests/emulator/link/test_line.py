"""The line in virtual time, with a stand-in unit: bytes take ten bit times each (8N1),
answers are serialized from the instant a unit emits them, reads wait virtually up to
their timeout, units' deadlines are honoured, and every byte goes to the transcript."""

from __future__ import annotations

import io

import pytest

from emulator.link.line import Line, byte_time
from gve_fixtures.protocol import SECOND
from gve_fixtures.transcript import HOST, UNIT, parse
from tests.emulator.link.fake_unit import DELAY_NS, FakeUnit

BAUD = 9600
B = round(10 * SECOND / BAUD)        # one byte: start bit, 8 data bits, stop bit


def line_with(*units: FakeUnit, log: io.StringIO | None = None) -> Line:
    return Line(list(units) or [FakeUnit()], BAUD, log=log)


def test_byte_time_is_ten_bits() -> None:
    assert byte_time(9600) == B == 1_041_667
    assert byte_time(115200) == 86_806


def test_write_takes_the_transmission_time_and_units_see_each_byte_complete() -> None:
    unit = FakeUnit()
    line = line_with(unit)
    assert line.write(b"!0?\r") == 4
    assert line.now == 4 * B
    assert unit.received == [(b"!0?\r", 4 * B)]


def test_answer_arrives_at_the_baud_rate_from_the_instant_it_is_emitted() -> None:
    line = line_with()
    line.write(b"!0?\r")
    assert line.in_waiting == 0                 # emitted at 4B, first byte complete at 5B
    line.advance_to(5 * B)
    assert line.in_waiting == 1
    assert line.read(2, timeout=0.0) == b"0"
    assert line.read(1, timeout=1.0) == b"\r"
    assert line.now == 6 * B                    # the read waited exactly until the byte
    assert line.read(2, timeout=0.5) == b""     # like pyserial: short only at the timeout
    assert line.now == 6 * B + SECOND // 2


def test_read_until_stops_at_the_terminator_and_waits_only_as_long_as_needed() -> None:
    line = line_with()
    line.write(b"!0?\r!0?\r")
    assert line.read_until(b"\r", timeout=1.0) == b"0\r"
    assert line.now == 8 * B                    # the write itself took 8 byte times
    assert line.read_until(b"\r", timeout=1.0) == b"0\r"
    assert line.now == 10 * B


def test_read_with_nothing_coming_returns_after_the_timeout_in_virtual_time() -> None:
    line = line_with()
    assert line.read(1, timeout=0.25) == b""
    assert line.now == SECOND // 4
    assert line.read(1, timeout=0.0) == b""
    assert line.now == SECOND // 4


def test_a_frame_for_another_address_gets_no_answer() -> None:
    line = line_with(FakeUnit(3))
    line.write(b"!0?\r")
    assert line.read_until(b"\r", timeout=0.1) == b""


def test_answers_emitted_together_are_serialized_one_after_the_other() -> None:
    a, b = FakeUnit(0), FakeUnit(0)
    line = line_with(a, b)
    line.write(b"!0?\r")
    # both emit at 4B; the second answer waits for the first to leave the wire
    assert line.read(4, timeout=1.0) == b"0\r0\r"
    assert line.now == 8 * B


def test_reads_honour_unit_deadlines() -> None:
    unit = FakeUnit()
    line = line_with(unit)
    line.write(b"!0W\r")
    assert line.read_until(b"\r", timeout=1.0) == b"0\r"
    assert line.read_until(b"\r", timeout=0.05) == b""          # not due yet
    assert line.read_until(b"\r", timeout=1.0) == b"2\r"
    assert line.now == 4 * B + DELAY_NS + 2 * B
    assert 4 * B + DELAY_NS in unit.advanced                     # woken at its deadline


def test_advance_and_run_until_idle() -> None:
    line = line_with()
    line.write(b"!0W\r")
    assert line.run_until_idle(max_seconds=0.01) is False
    assert line.now == 4 * B + SECOND // 100
    assert line.run_until_idle() is True
    assert line.now == 4 * B + DELAY_NS
    assert line.next_deadline() is None
    line.advance(0.5)
    assert line.now == 4 * B + DELAY_NS + SECOND // 2
    assert line.read(4, timeout=0.0) == b"0\r2\r"


def test_rig_access_goes_to_the_addressed_unit() -> None:
    u0, u5 = FakeUnit(0), FakeUnit(5)
    line = line_with(u0, u5)
    line.advance(1.0)
    line.set_input(1, 0xFE, address=5)
    line.set_switch("Y", -1500)
    line.power_on(5)
    assert u5.inputs == {1: 0xFE} and u0.inputs == {}
    assert u0.switches == {"Y": -1500}
    assert u5.powered == [SECOND] and u0.powered == []
    assert line.state(5) == {"address": 5, "t": SECOND, "inputs": {1: 0xFE}}
    line.power_on()
    assert u0.powered == [SECOND]
    with pytest.raises(KeyError):
        line.state(2)


def test_the_transcript_logs_both_directions_with_their_instants() -> None:
    log = io.StringIO()
    line = line_with(log=log)
    line.write(b"!0?\r")
    line.read_until(b"\r", timeout=1.0)
    records = parse(log.getvalue()).records
    assert [(r.direction, r.data) for r in records] == [(HOST, b"!0?\r"), (UNIT, b"0\r")]
    assert records[0].t == B                    # first byte of the frame complete
    assert records[1].t == 5 * B                # first byte of the answer complete


def test_a_unit_at_another_rate_neither_hears_nor_is_heard() -> None:
    unit = FakeUnit()
    line = Line([unit], 9600)
    unit.set_rate_switch(19200)
    line.power_on()
    line.write(b"!0V1\r")
    assert unit.received == [] and line.read(10, 1.0) == b""
    line.baud, line.byte_ns = 19200, byte_time(19200)
    line.write(b"!0V1\r")
    assert line.read(10, 1.0, b"\r") == b"0\r"
    unit.received.clear()
    line.baud, line.byte_ns = 9600, byte_time(9600)
    unit.emit(b"0\r", line.now)                 # what it sends at 19200 is lost at 9600
    assert line.read(10, 1.0) == b""
