"""The technician's side of a run on a real unit, driven through a pseudo-terminal: the
question before the first move, and the hand steps (done and verified by reading the
input port back, skipped, or done wrong and caught by the read-back)."""

from __future__ import annotations

import pytest

from tests.conformance.operator.terminal import EmulatedUnit, Terminal, suite

pytestmark = pytest.mark.pty

HAND_CASE = "10.3.inputs.level-after-clearing"      # grounds IN0 (ctx.operator)
GROUND = "Ground input IN0 (the X reference input) now, then press Enter; s to skip:"
RELEASE = "Release input IN0 (the X reference input) now, then press Enter; s to skip:"


@pytest.fixture
def unit():
    u = EmulatedUnit("GVE84-100")
    yield u
    u.close()


def _start(unit: EmulatedUnit, *extra: str) -> Terminal:
    term = Terminal(suite("--target", f"serial:{unit.path}", "--profile", "GVE84-100",
                          "--cases", "1.profile.version", "--cases", HAND_CASE,
                          "--no-reports", *extra))
    asked = term.expect("Move this machine? [y/N]")
    assert "IP84 v3 27.1.2010, Q 25020304, judged as GVE84-100" in asked
    assert "X ±2000, Y ±2000, Z ±2000" in asked and "destructive tests" in asked
    return term


def test_no_confirmation_moves_nothing(unit):
    term = _start(unit)
    term.answer("n")
    assert term.finish() == 2
    assert "motion not confirmed, nothing that moves was sent" in term.seen
    assert "case runs" not in term.seen


def test_hand_steps_done_are_verified(unit):
    term = _start(unit)
    term.answer("y")
    for _ in ("G", "D", "K", "R"):
        term.expect(GROUND)
        unit.rig("in 1 FE")                          # the technician grounds IN0
        term.answer("")
        term.expect("verified: I1 = FE")
        term.expect(RELEASE)
        unit.rig("in 1 FF")
        term.answer("")
        term.expect("verified: I1 = FF")
    term.expect(f"PASS            {HAND_CASE} [GVE84-100]")
    assert term.finish() == 0 and "PASSED" in term.seen


def test_a_skipped_step_is_could_not_test_with_the_reason(unit):
    term = _start(unit)
    term.answer("y")
    term.expect(GROUND)
    term.answer("s")
    term.expect(f"COULD-NOT-TEST  {HAND_CASE} [GVE84-100]  -- could not test: Ground input "
                "IN0 (the X reference input): skipped by the operator")
    assert term.finish() == 0                        # never a FAIL


def test_a_wrong_action_is_caught_by_the_read_back(unit):
    term = _start(unit)
    term.answer("y")
    term.expect(GROUND)
    unit.rig("in 1 FD")                              # IN1 grounded instead of IN0
    term.answer("")
    term.expect(f"COULD-NOT-TEST  {HAND_CASE} [GVE84-100]  -- could not test: Ground input "
                "IN0 (the X reference input): not verified, I1 reads FD (IN0 should read 0)")
    assert term.finish() == 0


def test_yes_skips_the_question_and_no_operator_says_why(unit):
    term = Terminal(suite("--target", f"serial:{unit.path}", "--profile", "GVE84-100",
                          "--cases", HAND_CASE, "--cases", "1.profile.version",
                          "--no-reports", "--yes", "--no-operator"))
    term.expect(f"COULD-NOT-TEST  {HAND_CASE} [GVE84-100]  -- could not test: needs a hand")
    assert term.finish() == 0 and "Move this machine?" not in term.seen
