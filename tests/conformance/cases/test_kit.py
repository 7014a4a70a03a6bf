"""A case that relies on a feature configured in EEPROM establishes it first (`configured`):
every parameter its manual names read, only those out of range written (with
--allow-destructive; put back after the case), else COULD-NOT-TEST saying which, or
(where the case allows) judged as found under the rule of that reading."""

from __future__ import annotations

from conformance.link.framing import frame
from conformance.run.runner import run
from conformance.run.selection import select
from conformance.verdicts.verdict import COULD_NOT_TEST, PASS
from tests.conformance.cases.used import used_unit

CASES = ["10.cmd.mpg.modes", "9.reset.mpg-enabled"]


def test_without_destructive_commands_the_hand_wheel_is_judged_as_found_by_the_reading():
    """An MPG parameter out of range and no leave to write it: Y is still tried, graded
    by the rule of that silence (the MPG "cannot be used"), and nothing is written."""
    unit = used_unit("GVE114-500")
    result = run([unit], select(CASES))
    (modes,) = [r for r in result.results if r.id == "10.cmd.mpg.modes"]
    assert modes.verdict == PASS, modes.notes
    rules = {c["rule"] for c in modes.checks}
    assert "9.reset.mpg-parameters" in rules and "10.cmd.mpg" in rules
    assert not [line for line in modes.wire_log if "EFW" in line or "EW" in line]
    (moving,) = [r for r in result.results if r.id == "9.reset.mpg-enabled"]
    assert moving.verdict == COULD_NOT_TEST


def test_a_required_feature_that_needs_a_write_cannot_test_and_says_which():
    # a unit whose EW answers 0 and keeps the byte: the hand wheel cannot be enabled
    unit = used_unit("GVE114-500", allow_destructive=True, mutant="eeprom-write-lost")
    result = run([unit], select(["9.reset.mpg-enabled"]))
    (moving,) = result.results
    assert moving.verdict == COULD_NOT_TEST, moving.notes
    assert "mpg needs lower limit X (EEPROM 10: 0..10000): EFW10,0 was taken, yet it reads" \
        in moving.notes[0]


def test_every_parameter_out_of_range_is_written_and_put_back_after_the_case():
    unit = used_unit("GVE114-500", allow_destructive=True)
    # the owner set the delay already (in the checksum mode the owner left on)
    assert summed(unit, "EUW48,250") == b"0,5C\r"
    before = unit.state()["eeprom"]
    result = run([unit], select(CASES))
    assert {r.id: r.verdict for r in result.results} == dict.fromkeys(CASES, PASS)
    (modes,) = [r for r in result.results if r.id == "10.cmd.mpg.modes"]
    written = [line.split("> !0", 1)[1].split("\\r")[0] for line in modes.wire_log
               if "> !0E" in line and "W" in line.split("> !0", 1)[1][:3]]
    # the enable last, every other parameter out of range before it; the delay in range
    assert written[-1] == "EW06,01" and not [w for w in written if w.startswith("EUW48")]
    assert {w[:5] for w in written} >= {"EFW10", "EFW2C", "EFW3C", "EFW40", "EFW44", "EFW60"}
    assert result.problems == []
    assert unit.state()["eeprom"] == before


def summed(unit, body: str) -> bytes:
    unit.port.write(frame(body, 0, True))
    return unit.port.read_until(b"\r")
