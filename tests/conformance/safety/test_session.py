"""The session on a real unit, end to end, with the emulator in process on the wall
clock behind a serial-like target (tests/conformance/safety/units.py): the unit is left
as found, EEPROM byte for byte, and Ctrl-C sends H, then D, before anything else."""

from __future__ import annotations

import os
import random

import pytest

from conformance.run.runner import run
from conformance.run.selection import select
from conformance.verdicts.verdict import COULD_NOT_TEST, ERROR, FAIL
from tests.conformance.safety.units import in_process_unit

#: frames that can start motion (R only gives back a K a case left: the physical check
#: after Ctrl-C would see it if it moved anything)
MOTION = (b"L", b"C", b"G", b"W", b"*E", b"SW6")


def body(frame: bytes) -> bytes:
    return frame[2:].split(b",")[0] if frame[2:3] != b"S" else frame[2:]


def moves(frame: bytes) -> bool:
    text = frame[2:-1]
    return text.startswith(MOTION) and not text.startswith((b"L0,0,0", b"C0,0,0"))


def random_eeprom(seed: str) -> bytes:
    """Random bytes, but 06 = FF: other values may turn the GVE114's hand-wheel (MPG)
    mode on, and a unit in that mode reports RUN (spec 9), which the suite refuses."""
    data = bytearray(random.Random(seed).randbytes(256))
    data[6] = 0xFF
    return bytes(data)


def test_a_unit_found_moving_is_not_taken_over(tmp_path):
    image = tmp_path / "unit.eeprom"
    image.write_bytes(b"\xff" * 6 + b"\x01" + b"\xff" * 249)   # MPG enabled: RUN = 1
    unit = in_process_unit("GVE114-500", eeprom=str(image))
    result = run([unit], select(["5.errors.*"]))
    assert {r.verdict for r in result.results} == {COULD_NOT_TEST}
    assert result.problems and "ST6 = 40" in result.problems[0]
    assert not [f for f in unit.frames if moves(f) or f.startswith(b"!0H")]


def test_the_unit_is_left_as_found():
    unit = in_process_unit("GVE84-100", max_travel=500)
    for frame in (b"!0NX1234\r", b"!0NY-5\r", b"!0SW2,05\r", b"!0SW1,03\r", b"!0SW0,1A\r",
                  b"!0%+\r"):
        unit.recorder.write(frame)          # the machine's own settings, before the run
        unit.recorder.read_until(b"\r")
    before = unit.state()
    result = run([unit], select(["10.3.status.*", "6.checksum.*", "5.errors.busy"]))
    after = unit.state()
    assert not any(r.verdict in (FAIL, ERROR) for r in result.results)
    assert after["status"][:6] == before["status"][:6] == ["1A", "03", "05", "00", "00", "00"]
    assert after["checksums"] is True
    assert after["physical"] == [0, 0, 0]    # back where the run began
    assert after["position"] == [1234, -5, 0]  # counters as found
    report = result.sessions[unit.info.spec]
    assert report["problems"] == [] and report["identity"]["version"] == "IP84 v3 27.1.2010"
    assert any("1A 03 05 00 00 00" in line for line in report["restored"])


def test_gve54_micro_steps_are_reset_before_every_case_and_at_the_end():
    unit = in_process_unit("GVE54", max_travel=500)
    # cases that leave another mode set, one after the other (the rest of 10.7 sets the
    # modes the same way, in real time: half a minute more), and cases that set none
    result = run([unit], select(["1.profile.*", "10.7.microstep.current-apart",
                                 "10.7.microstep.positions-in-sixteenths",
                                 "10.7.motor.modes-while-moving", "11.golden.g5b*"]))
    assert unit.state()["microstep"] in ("F", 1)  # the reset mode, MF
    assert [f for f in unit.frames if f.startswith(b"!0MF")]
    assert any("micro-step" in line for line in result.sessions[unit.info.spec]["reset"])


@pytest.mark.parametrize(("profile", "globs"), [
    ("GVE114-500", ["10.6.*", "10.machine.queue-status-eeprom"]),
    ("GVE84-100", ["11.golden.g9*", "10.6.eeprom.round-trip"]),
])
def test_a_destructive_run_leaves_random_eeprom_byte_for_byte(tmp_path, profile, globs):
    image = tmp_path / "unit.eeprom"
    image.write_bytes(random_eeprom(profile))
    found = image.read_bytes()
    unit = in_process_unit(profile, allow_destructive=True, eeprom=str(image))
    result = run([unit], select(globs))
    assert any(f.startswith((b"!0EW", b"!0EFW", b"!0EUW")) for f in unit.frames)
    assert image.read_bytes() == found
    assert result.problems == []
    assert any("EEPROM: 256 of 256 bytes verified, read back as found" in line
               for line in result.sessions[unit.info.spec]["restored"])


def _ctrl_c_at(unit, trigger) -> int:
    """Press Ctrl-C while the first frame ``trigger(index, frame)`` picks is in flight."""
    pressed = []

    def hook(i: int, frame: bytes) -> None:
        if not pressed and trigger(i, frame):
            pressed.append(i)
            unit.session.interrupts.signal()
        elif pressed and i == pressed[0] + 2:           # H has been answered: stopped
            pressed.append(unit.state()["physical"])
    unit.on_frame = hook
    return pressed


def _after_ctrl_c(unit, pressed) -> list[bytes]:
    assert pressed, "the trigger never fired"
    after = unit.frames[pressed[0] + 1:]
    assert [f[2:3] for f in after[:2]] == [b"H", b"D"], after[:4]
    assert not [f for f in after if moves(f)], "motion after Ctrl-C"
    assert unit.state()["physical"] == pressed[1], "the axes moved after H"
    return after


def test_ctrl_c_inside_a_packet_on_a_unit_that_ends_packets_only_with_e():
    # H goes first; taken as a member (no answer), the packet is closed with a *E every
    # unit refuses and H goes again, then D
    unit = in_process_unit("GVE84-100", readings=("packet-closed-only-by-end",))
    members = []

    def trigger(i: int, frame: bytes) -> bool:
        if frame.startswith(b"!0*S"):
            members.append(i)
        return bool(members) and frame.startswith(b"!0C")
    pressed = _ctrl_c_at(unit, trigger)
    result = run([unit], select(["7.packet.commits-all"]))
    assert pressed and result.interrupted
    after = [f[2:-1] for f in unit.frames[pressed[0] + 1:]]
    assert after[:4] == [b"H", b"*E-1", b"H", b"D"], after[:6]
    assert unit.state()["physical"] == [0, 0, 0]
    assert unit.state()["packet_open"] is False


@pytest.mark.parametrize("seed", range(3))
def test_ctrl_c_inside_a_hypothesis_machine_halts_first(tmp_path, seed):
    unit = in_process_unit("GVE84-100", max_travel=500)
    pick = random.Random(seed).randrange(1, 40)
    seen: list[bytes] = []                 # frames since the machine's first @

    def trigger(i: int, frame: bytes) -> bool:
        if seen or frame == b"!0@\r":
            seen.append(frame)
        return len(seen) >= pick
    pressed = _ctrl_c_at(unit, trigger)
    result = run([unit], select(["7.machine.packets", "8.index.*"]))
    _after_ctrl_c(unit, pressed)
    assert result.interrupted and result.results[-1].interrupted
    assert result.results[-1].id == "7.machine.packets"
    assert unit.state()["status"][:6] == ["00"] * 6


@pytest.mark.parametrize("when", ["backup", "case", "restore"])
def test_ctrl_c_during_eeprom_work_halts_first_and_restores(tmp_path, when):
    image = tmp_path / "unit.eeprom"
    image.write_bytes(random_eeprom(when))
    found = image.read_bytes()
    unit = in_process_unit("GVE114-500", allow_destructive=True, eeprom=str(image))
    seen = {"EW": 0}

    def trigger(i: int, frame: bytes) -> bool:
        if frame.startswith((b"!0EW", b"!0EFW", b"!0EUW")):
            seen["EW"] += 1
        return {"backup": frame.startswith(b"!0ER7F"),
                "case": seen["EW"] == 2,
                "restore": seen["EW"] >= 2 and frame.startswith(b"!0ER80")
                and unit.session.finished}[when]
    pressed = _ctrl_c_at(unit, trigger)
    result = run([unit], select(["10.6.*", "10.machine.queue-status-eeprom"]))
    _after_ctrl_c(unit, pressed)
    assert result.interrupted
    if when == "restore":               # a signal during the restorations stops them
        assert any("stopped by Ctrl-C" in p for p in result.problems)
    else:
        assert image.read_bytes() == found
        assert result.problems == []
    assert os.path.exists(image)


def test_the_operator_is_asked_once_before_the_first_motion_with_the_identity_known():
    unit = in_process_unit("GVE84-100", max_travel=500)
    asked = []
    unit.session.before_motion = lambda: asked.append(
        (unit.session.identity["version"], [f for f in unit.frames if moves(f)]))
    run([unit], select(["1.profile.*", "5.errors.ok", "10.1.*"]))
    assert asked == [("IP84 v3 27.1.2010", [])]       # before any frame that moves
    assert [f for f in unit.frames if moves(f)]


def test_the_line_round_trip_is_measured_at_the_start():
    unit = in_process_unit("GVE84-100", max_travel=500)
    result = run([unit], select(["1.profile.*"]))
    line = result.sessions[unit.info.spec]["line"]
    assert line["byte_ms"] == pytest.approx(10 / 115200 * 1e3)
    # a `?` frame (4 bytes) and its answer take at least their bytes' time
    assert 4 * line["byte_ms"] < line["min_ms"] <= line["median_ms"] <= line["max_ms"]
    # the `?` exchange's bytes: `!0?\r` and `0,IP84 v3 27.1.2010\r`
    assert line["bytes_ms"] == pytest.approx((4 + 20) * line["byte_ms"])


def test_every_link_of_a_real_session_carries_the_measured_line():
    unit = in_process_unit("GVE84-100", max_travel=500)
    link = unit.open_link()
    assert link.round_trip == unit.session.report.line and link.round_trip["max_ms"] > 0
    unit.session.finish()


def test_a_measured_line_lengthens_the_answer_timeout_by_twice_its_slowest_round_trip():
    unit = in_process_unit("GVE84-100", max_travel=500)
    link = unit.open_link()
    measured = link.answer_timeout("V1000", 8)
    link.round_trip = {}
    assert measured - link.answer_timeout("V1000", 8) == \
        pytest.approx(2 * unit.session.report.line["max_ms"] / 1e3)
    unit.session.finish()


def test_a_hand_wheel_an_eeprom_write_made_effective_is_stopped_and_put_back():
    """EEPROM 06 enabling the GVE114's MPG (on after reset) holds the axes: the stop after
    the case turns it off, so `D` clears the INTA of its `H` and 06 is written back; the
    next known state has INTA clear and the MPG in its reset mode."""
    unit = in_process_unit("GVE114-500", allow_destructive=True)
    session = unit.begin()
    link = session.open_link()
    assert link.send("EW06,01").code == 0
    assert link.send("SR6").hex() & 0x40                      # RUN: the MPG holds the axes
    session.after_case()
    link = session.open_link()
    assert link.send("SR6").hex() == 0                        # no INTA left by the stop
    assert link.send("ER06").hex() == 0xFF
    assert unit.state()["mpg"] == "&"
    session.finish()
    assert session.report.problems == []
