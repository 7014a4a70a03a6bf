"""The run's verdict and its last line: PASSED only when nothing FAILed or ERRed, with
what was judged and what was not tested, grouped by reason (conformance/verdicts/untested.toml)."""

from __future__ import annotations

from dataclasses import dataclass, field

from conformance.verdicts.untested import OTHER, why
from conformance.verdicts.verdict import FAILED, INCOMPLETE, PASSED, last_line, not_tested, overall


@dataclass
class R:
    verdict: str
    notes: list[str] = field(default_factory=list)


RIG = R("COULD-NOT-TEST", ["needs a test rig (the emulator's, or an exec: simulator's "
                           "control channel)"])
ENVELOPE = R("COULD-NOT-TEST", ["safety stop: L900,0,0: axis X could reach 0..900 full "
                                "steps from where the run began, beyond the envelope ±500"])
LACKS = R("MISSING", ["the profile lacks EFW"])


def test_incomplete_says_what_was_judged_and_what_was_not_tested():
    results = [R("PASS")] * 120 + [R("NON-STRICT")] * 8 + [RIG] * 9 + [ENVELOPE] * 3
    assert last_line(results) == ("INCOMPLETE — 120 PASS, 8 NON-STRICT; not tested: 12 of "
                                  "140 (9 need a rig, 3 beyond the envelope)")


def test_only_what_the_profile_lacks_leaves_a_run_passed():
    assert last_line([R("PASS"), LACKS]) == ("PASSED — 1 PASS; not tested: 1 of 2 (1 not in "
                                             "the profile)")
    assert overall([R("PASS"), LACKS, RIG])[0] == INCOMPLETE
    declined = R("COULD-NOT-TEST", ["safety stop: L600,0,0: motion was not confirmed"])
    assert overall([R("PASS"), declined])[0] == INCOMPLETE


def test_everything_tested():
    assert overall([R("PASS"), R("INFO")]) == (PASSED, "1 PASS, 1 INFO; everything tested (2)")


def test_a_fail_or_an_error_is_failed_and_still_says_what_was_not_tested():
    verdict, reason = overall([R("PASS"), R("FAIL"), R("ERROR"), LACKS])
    assert verdict == FAILED
    assert reason == "1 ERROR, 1 FAIL, 1 PASS; not tested: 1 of 4 (1 not in the profile)"


def test_nothing_judged_is_failed():
    verdict, reason = overall([RIG, RIG])
    assert verdict == FAILED and reason.startswith("no case could judge the target; ")
    assert overall([])[0] == FAILED


def test_interrupted_and_problems_are_failed():
    assert overall([R("PASS")], interrupted=True)[0] == FAILED
    verdict, reason = overall([R("PASS")], problems=["EEPROM 10 not restored"])
    assert verdict == FAILED and "EEPROM 10 not restored" in reason


def test_reasons_come_from_the_notes():
    assert why(["safety stop: L5: motion was not confirmed"]) == "motion not confirmed"
    assert why(["destructive: needs --allow-destructive"]) == \
        "destructive, need --allow-destructive"
    assert why(["could not test: needs a hand: ground input IN0 (X reference)"]) == \
        "need a hand at the unit"
    assert why(["missing: the profile lacks W"]) == "not in the profile"
    assert why(["something nobody foresaw"]) == OTHER


def test_a_case_that_needs_a_reset_says_what_to_run_with():
    """A real unit is restarted with J only with --allow-destructive: the last line
    says so rather than "for another reason"."""
    phrase = why(["could not test: needs a reset (J): run with --allow-destructive"])
    assert phrase != OTHER and "reset" in phrase and "--allow-destructive" in phrase


def test_results_no_pattern_matches_are_counted_as_one_reason():
    odd = R("COULD-NOT-TEST", ["something nobody foresaw"])
    assert not_tested([R("PASS"), odd, odd]) == (
        "not tested: 2 of 3 (2 for another reason (each case's note says which))")


def test_an_interrupted_run_never_says_everything_was_tested():
    verdict, reason = overall([R("FAIL")] * 3, interrupted=True)
    assert verdict == FAILED and "everything tested" not in reason
    assert reason == "3 FAIL; 3 run before the interruption, nothing after it"
    assert overall([R("PASS")], interrupted=True)[1] == (
        "interrupted before every case had run; 1 PASS; 1 run before the interruption, "
        "nothing after it")


def test_missing_is_what_the_profile_lacks_whatever_its_note():
    assert overall([R("PASS"), R("MISSING", ["no packets on the GVE54"])])[0] == PASSED
