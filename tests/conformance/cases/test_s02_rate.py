"""The line-rate cases: every rate the profile lists reached through the switch (and the
GVE114's EEPROM 0D) and a power cycle, the host following; each mutant of the rate
caught through the check of the rule it breaks; the reading of an unlisted 0D byte graded
NON-STRICT with the unit found and put back; a target whose line carries no rate, or
whose rate is fixed at order time, not judged."""

from __future__ import annotations

import shlex
import sys

import pytest

from conformance.run.runner import run_case
from conformance.run.selection import select
from conformance.targets import parse_target
from conformance.verdicts.verdict import COULD_NOT_TEST, MISSING, NON_STRICT, PASS
from tests.conformance.cases.catching import assert_catches

CASES = ("2.link.rate.every-listed-rate", "2.link.rate.read-at-power-on",
         "2.link.rate.unlisted-range")

#: mutant -> (the case made to catch it, the rule of its failing check, the profiles)
CATCHES = {
    "baud-range-ignored": ("2.link.rate.every-listed-rate", "2.link.rate-by-switch",
                           ("GVE114-500", "GVE114-50")),
    "baud-read-at-restart": ("2.link.rate.read-at-power-on", "2.link.rate-read-at-power-on",
                             ("GVE114-125", "GVE54")),
    "baud-jumpers-ignored": ("2.link.rate.every-listed-rate", "2.link.rate-by-switch",
                             ("GVE54",)),
    "baud-range-read-at-restart": ("2.link.rate.read-at-power-on",
                                   "2.link.rate-range-at-restart", ("GVE114-200",)),
}


def _case(case_id: str):
    (c,) = select([case_id])
    return c


@pytest.mark.parametrize(("mutant", "profile"),
                         [(m, p) for m, (_, _, ps) in CATCHES.items() for p in ps])
def test_the_case_catches_its_mutant(mutant: str, profile: str) -> None:
    case_id, rule, _ = CATCHES[mutant]
    # on our emulator the GVE54 table's [D] rule FAILs beside the manual's rule
    assert_catches(case_id, rule, mutant, profile, only=mutant != "baud-jumpers-ignored")


@pytest.mark.parametrize("case_id", CASES)
def test_the_clean_gve114_passes_at_every_rate(case_id: str) -> None:
    result = run_case(_case(case_id), parse_target("emu:GVE114-500"), "ci")
    assert result.verdict == PASS
    reached = [k["what"] for k in result.checks if "answers at" in k["what"]]
    assert reached and all(k["ok"] for k in result.checks)


def test_every_listed_rate_is_reached() -> None:
    for profile in ("GVE114-500", "GVE54"):
        result = run_case(_case(CASES[0]), parse_target(f"emu:{profile}"), "ci")
        bauds = parse_target(f"emu:{profile}").profile.bauds
        said = " ".join(k["what"] for k in result.checks)
        assert result.verdict == PASS
        assert all(f"answers at {b}" in said for b in bauds), (profile, said)


def test_a_rate_fixed_at_order_time_is_not_in_the_profile() -> None:
    for case_id in CASES:
        assert run_case(_case(case_id), parse_target("emu:GVE84-100"), "ci").verdict \
            == MISSING


def test_the_reading_of_an_unlisted_range_byte_is_non_strict_and_the_unit_put_back() -> None:
    target = parse_target("emu:GVE114-500?reading=baud-unlisted-high")
    result = run_case(_case(CASES[2]), target, "ci")
    assert result.verdict == NON_STRICT
    failed = {k["rule"] for k in result.checks if not k["ok"]}
    assert failed == {"2.link.rate-range-unlisted"}
    assert any("answers at 921600" in n for n in result.notes)
    restored = [k for k in result.checks if "again" in k["what"] or "restored" in k["what"]]
    assert restored and all(k["ok"] for k in restored)


@pytest.mark.parametrize("case_id", CASES[:2])
def test_gve54_jumpers_in_another_order_are_non_strict_and_followed(case_id: str) -> None:
    # the manual lists no rate for its jumpers: the order is the profile's [D] table
    result = run_case(_case(case_id), parse_target("emu:GVE54?reading=rate-jumpers-reversed"),
                      "ci")
    assert result.verdict == NON_STRICT
    assert {k["rule"] for k in result.checks if not k["ok"]} == {"2.link.rate-jumper-table"}
    restored = [k for k in result.checks if "again" in k["what"]]
    assert restored and all(k["ok"] for k in restored)


def test_a_line_that_carries_no_rate_could_not_test_and_changes_nothing() -> None:
    command = [sys.executable, "-m", "emulator", "--model", "GVE114-500", "--pty"]
    target = parse_target("exec:" + shlex.join(command), profile="GVE114-500",
                          allow_destructive=True, max_travel=2000)
    target.preflight()
    result = run_case(_case(CASES[0]), target, "ci")
    assert result.verdict == COULD_NOT_TEST
    assert "carries no rate" in result.notes[0]


def _cosim(profile: str, *extra: str):
    command = [sys.executable, "-m", "emulator", "--model", profile, "--cosim", *extra]
    target = parse_target("exec:" + shlex.join(command), profile=profile,
                          allow_destructive=True, max_travel=2000)
    target.preflight()
    return target


def test_through_the_co_simulator_the_host_follows_with_baud_and_the_unit_is_put_back() -> None:
    assert run_case(_case(CASES[1]), _cosim("GVE54"), "ci").verdict == PASS
    broken = run_case(_case(CASES[1]), _cosim("GVE54", "--mutant", "baud-read-at-restart"),
                      "ci")
    failed = {k["rule"] for k in broken.checks if not k["ok"]}
    assert failed == {"2.link.rate-read-at-power-on"}
