"""Every command of spec 10 on every profile that has it, its refusal (3) on the others,
and the rules of spec 3-10 the emulator implements. Expected answers come from the spec."""

from __future__ import annotations

import re
import struct

import pytest

from gve_fixtures.profile import available_profiles, load_profile
from tests.emulator.replay import open_line

PROFILES = available_profiles()

# command -> (a valid frame body on an idle unit at reset, the answer it gets) [spec 10]
SAMPLES: dict[str, tuple[str, str | None]] = {
    "?": ("?", r"0,.+"), "Q": ("Q", r"0,\d{8}"),
    "L": ("L10,0,0", "0"), "C": ("C10,0,0", "0"),
    "T": ("T10", "0"), "$": ("$100", "0"), "A": ("A100", "0"), "V": ("V1000", "0"),
    "VL": ("VL1000,1000,1000", "0"), "B": ("B1000", "0"), "VK": ("VK", "0"), "VN": ("VN", "0"),
    "XA": ("XA", "0"), "XU": ("XU", "0"), "XD": ("XD", "0"), "XM": ("XM200", "0"),
    "P": ("P", r"0,0,0"), "PF": ("PF", r"0,0,0,0"),
    "N": ("N", "0"), "NX": ("NX100", "0"), "NY": ("NY-5", "0"), "NZ": ("NZ0", "0"),
    "NA": ("NA7", "0"),
    "W": ("WX,-100,1000,100,500", "5"),      # no switch on the way [D]
    "K": ("K", "0"), "R": ("R", "0"), "H": ("H", "8"), "D": ("D", "0"), "G": ("G", "6"),
    "ER": ("ER01", r"0,[0-9A-F]{2}"), "EW": ("EW40,12", "0"),
    "EFR": ("EFR30", r"0,\S+"), "EFW": ("EFW30,1.5", "0"),
    "EUR": ("EUR4C", r"0,\d+"), "EUW": ("EUW4C,123", "0"),
    "O0": ("O0,FB", "0"), "I0": ("I0", "0,FF"), "I1": ("I1", "0,FF"), "I2": ("I2", "0,FF"),
    "SR": ("SR0", "0,00"), "SW": ("SW0,00", "0"), "F": ("F", "0,00"),
    "M": ("M4", "0"), "Y": ("Y-", "0,Y-"), "@": ("@", r"0,\d+"), ">": (">", "0"),
    "J": ("J", "0"), "%": ("%-", "0"), "*S": ("*S", None), "*E": ("*E0", "4,0"),
}


def ask(port, body: str, address: int = 0) -> bytes:
    port.write(f"!{address}{body}\r".encode())
    return port.read_until(b"\r")


@pytest.fixture(params=PROFILES)
def profile(request):
    return load_profile(request.param)


def test_every_command_of_the_profile_and_the_refusal_of_the_others(profile):
    for name, (body, answer) in SAMPLES.items():
        port = open_line(profile.name)
        got = ask(port, body)
        if name not in profile.commands:
            assert got == b"3\r", f"{profile.name} lacks {name}: {body} -> {got!r}"
        elif answer is None:
            assert got == b"", f"{body} is not answered"
        else:
            assert re.fullmatch(answer.encode() + b"\r", got), f"{body} -> {got!r}"


@pytest.mark.parametrize("body", ["v1000", "l10,0,0", "Z", "E", "X"])
def test_unknown_and_lower_case_commands_are_3(profile, body):
    assert ask(open_line(profile.name), body) == b"3\r"


@pytest.mark.parametrize("body", ["V+100", "V 100", "V", "V1e3", "L1,2", "L1,,2", "SW1",
                                  "ERG1", "T5,5", "A-"])
def test_syntax_errors_are_4(profile, body):
    assert ask(open_line(profile.name), body) == b"4\r"


@pytest.mark.parametrize("body", ["SW8,F1", "T25", "T0", "A0", "A10001", "V9", "SR7"])
def test_out_of_range_is_5(profile, body):
    assert ask(open_line(profile.name), body) == b"5\r"


def test_frames_for_another_address_are_ignored(profile):
    port = open_line(profile.name)
    other = 1 if profile.address != 1 else 2
    port.write(f"!{other}V1000\r!{other}?\r".encode())
    port.line.advance(1.0)
    assert port.in_waiting == 0
    assert ask(port, "@") == b"0,0\r"


def test_noise_bang_restart_and_lf(profile):
    port = open_line(profile.name)
    port.write(b"xx\n\x00!0V1!0?\r\n")
    assert port.read_until(b"\r").startswith(b"0," + profile.version.encode())
    port.line.advance(0.5)
    assert port.in_waiting == 0
    assert ask(port, "@") == b"0,1\r"          # the dropped frame did not count


def test_frame_longer_than_96_bytes_is_4(profile):
    assert ask(open_line(profile.name), "V" + "0" * 100 + "1") == b"4\r"


def test_watchdog_answers_2_and_a_lone_bang_nothing(profile):
    port = open_line(profile.name)
    port.write(b"!0V10")
    port.line.advance(0.2)
    assert port.read(2) == b"2\r"
    port.write(b"!")
    port.line.advance(0.2)
    assert port.in_waiting == 0
    assert ask(port, "@") == b"0,0\r"


def test_watchdog_time_is_configurable():
    port = open_line("GVE84-100", watchdog_ms="500")
    port.write(b"!0V10")
    port.line.advance(0.3)
    assert port.in_waiting == 0
    port.line.advance(0.3)
    assert port.read(2) == b"2\r"


def test_queue_full_and_l_while_busy(profile):
    port = open_line(profile.name)
    for _ in range(profile.buffer):
        assert ask(port, "C60000,0,0") == b"0\r"
    assert ask(port, "C60000,0,0") == b"1\r"
    assert ask(port, "F") == b"0,60\r"               # RUN + queue full
    assert ask(port, "L0,0,0") == b"1\r"


def test_l00_idiom_waits_until_done(profile):
    port = open_line(profile.name)
    assert ask(port, "L100,0,0") == b"0\r"
    assert ask(port, "L0,0,0") == b"1\r"
    port.line.advance(2.0)
    assert ask(port, "L0,0,0") == b"0\r"
    assert ask(port, "PF") == b"0,%d,0,0\r" % (100 * (profile.position_scale
                                                          if profile.microstep else 1) // (
        16 if profile.microstep else 1))


def test_halt_go_resume_loses_no_step(profile):
    port = open_line(profile.name)
    for _ in range(3):
        ask(port, "C500,0,0")
    port.line.advance(0.3)
    assert ask(port, "H") == b"8\r"
    assert ask(port, "SR6") == b"8,D0\r"
    assert ask(port, "V1000") == b"8\r"             # INTA bit on every response
    assert ask(port, "G") == b"0\r"
    assert ask(port, "G") == b"6\r"
    port.line.advance(5)
    assert ask(port, "P") == b"0,1500,0\r"


def test_delete_refused_while_moving_and_clears_after_halt(profile):
    port = open_line(profile.name)
    ask(port, "C2000,0,0")
    port.line.advance(0.2)
    assert ask(port, "D") == b"7\r"
    assert ask(port, "N") == b"7\r"
    assert ask(port, "H") == b"8\r"
    assert ask(port, "N") == b"F\r"                 # RUN = 1 while the rest is queued
    assert ask(port, "D") == b"0\r"
    assert ask(port, "SR6") == b"0,00\r"


def test_keep_takes_only_l_on_gve84_and_gve114(profile):
    port = open_line(profile.name)
    ask(port, "C2000,0,0")
    port.line.advance(0.2)
    ask(port, "H")
    assert ask(port, "K") == b"0\r"
    expected = b"4\r" if profile.keep == "single-L" else b"0\r"
    assert ask(port, "C10,0,0") == expected


#: short dialogues with a fresh unit: each frame and its answer, in order
DIALOGUES = {
    "restore without keep is an empty save": [("R", b"0\r"), ("SR6", b"0,00\r")],
    "status words store all bits": [("SW1,3F", b"0\r"), ("SR1", b"0,3F\r")],
}


@pytest.mark.parametrize("dialogue", sorted(DIALOGUES))
def test_short_dialogues(profile, dialogue):
    port = open_line(profile.name)
    frames = DIALOGUES[dialogue]
    assert [ask(port, body) for body, _ in frames] == [answer for _, answer in frames]


def test_interrupt_input_stops_motion_and_sets_the_cause(profile):
    port = open_line(profile.name)
    assert ask(port, "SW0,01") == b"0\r"
    ask(port, "C5000,0,0")
    port.line.advance(0.3)
    port.line.set_input(1, 0xFE)                    # IN0 grounded: active at polarity 0
    port.line.advance(1.0)
    assert ask(port, "SR4") == b"8,01\r"
    assert ask(port, "SR6")[:2] == b"8,"
    here = ask(port, "P")
    port.line.advance(1.0)
    assert ask(port, "P") == here                   # stopped
    assert ask(port, "G") == b"8\r"                 # still active: stops again [D]
    assert ask(port, "SR4") == b"8,01\r"


def test_checksum_mode(profile):
    port = open_line(profile.name)
    if "%" not in profile.commands:
        assert ask(port, "%+") == b"3\r"
        return
    assert ask(port, "%+") == b"0,5C\r"
    assert ask(port, "A100,4F") == b"0,5C\r"
    assert ask(port, "A100,4E") == b"4,60\r"         # '4,' sums to 0x60
    assert ask(port, "A100") == b"4,60\r"
    assert ask(port, "A100,4f") == b"0,5C\r"        # either case accepted [D]
    assert ask(port, "%-,CF") == b"0\r"


def test_packet_all_or_nothing(profile):
    if "*S" not in profile.commands:
        return
    port = open_line(profile.name)
    port.write(b"!0*S\r!0C10,0,0\r!0C10,0,0\r")
    assert ask(port, "*E3") == b"2,2\r"
    port.write(b"!0*S\r!0C10,0,0\r!0V100\r")
    assert ask(port, "*E2") == b"4,2\r"
    assert ask(port, "*E2") == b"4,0\r"
    port.write(b"!0*S\r!0B500\r!0C10,0,0\r")
    assert ask(port, "*E2") == b"0,2\r"
    port.line.advance(2)
    assert ask(port, "PF") == b"0,10,0,0\r"


def test_index_and_repeat(profile):
    port = open_line(profile.name)
    assert ask(port, ">") == b"0\r"
    ask(port, "V1000")
    ask(port, "T99")
    assert ask(port, "@") == b"0,2\r"
    port.write(b"!0>\r")
    assert port.read(20) == b"!0T99\r5\r"
    assert ask(port, "@") == b"0,2\r"


def test_j_answers_plain_0_and_restarts(profile):
    port = open_line(profile.name)
    ask(port, "V2000")
    assert ask(port, "J") == b"0\r"
    port.write(b"!0?\r")                             # lost: the unit restarts
    port.line.advance(profile.restart_ms / 1000 + 0.1)
    assert port.in_waiting == 0
    assert ask(port, "@") == b"0,0\r"


def test_eeprom_words(profile):
    if "EFW" not in profile.commands:
        return
    port = open_line(profile.name)
    assert ask(port, "EFW30,0.25") == b"0\r"
    assert ask(port, "EFR30") == b"0,0.25\r"
    assert ask(port, "ER30") == b"0,%02X\r" % struct.pack("<f", 0.25)[0]
    assert ask(port, "EUW4C,305419896") == b"0\r"
    assert ask(port, "ER4C") == b"0,78\r"
    assert ask(port, "EUR4C") == b"0,305419896\r"
    assert ask(port, "EFRFD") == b"5\r"
    assert ask(port, "EFW30,1e999") == b"5\r"          # not a finite float32 [D]


def test_eeprom_image_survives_a_restart_and_is_replaced_whole(tmp_path):
    image = tmp_path / "eeprom.bin"
    port = open_line("GVE84-100", eeprom=str(image))
    assert ask(port, "EW40,5A") == b"0\r"
    assert image.read_bytes()[0x40] == 0x5A and len(image.read_bytes()) == 256
    assert [p.name for p in tmp_path.iterdir()] == ["eeprom.bin"]   # no temporary left
    again = open_line("GVE84-100", eeprom=str(image))
    assert ask(again, "ER40") == b"0,5A\r"
    assert ask(again, "ER01") == b"0,00\r"           # GVE84 default: relay = spindle


def test_gve54_microstepping():
    port = open_line("GVE54", 1)
    assert ask(port, "M4", 1) == b"0\r"
    assert ask(port, "L100,100,100", 1) == b"0\r"
    port.line.advance(3)
    assert ask(port, "PF", 1) == b"0,400,400,400\r"
    assert ask(port, "MX", 1) == b"4\r"


def test_gve114_spindle_and_mpg():
    port = open_line("GVE114-500")
    assert ask(port, "V300", 7) == b"0\r"
    assert port.line.spindle() == 300
    assert ask(port, "L1,0,0", 7) == b"3\r"
    assert ask(port, "EW06,01") == b"0\r"            # MPG allowed: `&` after reset holds
    assert ask(port, "L1,0,0") == b"7\r"
    assert ask(port, "Y-") == b"0,Y-\r"
    assert ask(port, "L1,0,0") == b"0\r"


def test_two_units_share_a_line():
    import serial
    port = serial.serial_for_url("gve://?unit=GVE54@1&unit=GVE84-100@0", timeout=5)
    assert ask(port, "?", 1).startswith(b"0,Ip54")
    assert ask(port, "?", 0).startswith(b"0,IP84")
    port.line.advance(0.5)
    assert port.in_waiting == 0


def test_reference_run_finds_the_switch():
    port = open_line("GVE84-100")
    ask(port, "NY500")
    port.line.set_switch("Y", -1500)
    assert ask(port, "WY,-20000,1000,2000,500") == b"0\r"
    assert ask(port, "P") == b"0,0,0\r"
