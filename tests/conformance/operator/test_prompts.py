"""The technician's side of a run on a real unit, driven through a pseudo-terminal: the
question before the first frame that can move an axis, and the hand steps (done and
verified by reading the input port back, skipped, or done wrong and caught by the
read-back)."""

from __future__ import annotations

import json
import signal
import xml.etree.ElementTree as ET

import pytest

from conformance.cli.usage import INCOMPLETE_STATUS
from tests.conformance.operator.terminal import EmulatedUnit, Terminal, suite

pytestmark = pytest.mark.pty

HAND_CASE = "10.3.inputs.level-after-clearing"      # grounds IN0 (ctx.operator), then moves
MOVING_CASE = "10.2.motion.targets-reached"
GROUND = "Ground input IN0 (the X reference input) now, then press Enter; s to skip:"
RELEASE = "Release input IN0 (the X reference input) now, then press Enter; s to skip:"
QUESTION = "Move this machine? [y/N]"


@pytest.fixture
def unit():
    u = EmulatedUnit("GVE84-100")
    yield u
    u.close()


def _start(unit: EmulatedUnit, *cases: str) -> Terminal:
    return Terminal(suite("--target", f"serial:{unit.path}", "--profile", "GVE84-100",
                          "--cases", "1.profile.version", *(f"--cases={c}" for c in cases),
                          "--no-reports"))


def _asked(term: Terminal) -> None:
    asked = term.expect(QUESTION)
    assert "IP84 v3 27.1.2010, Q 25020304, judged as GVE84-100" in asked
    assert "X ±2000, Y ±2000, Z ±2000" in asked and "destructive tests" in asked


def test_no_confirmation_moves_nothing_and_the_run_is_incomplete(unit, tmp_path):
    """Motion declined at the question: nothing moves, and the run is not PASSED but
    INCOMPLETE, with its own exit status, on the console and in every report."""
    junit = tmp_path / "junit.xml"
    term = Terminal(suite("--target", f"serial:{unit.path}", "--profile", "GVE84-100",
                          "--cases", "1.profile.version", f"--cases={MOVING_CASE}",
                          "--report-dir", str(tmp_path), "--run-id", "declined",
                          "--junitxml", str(junit)))
    _asked(term)
    term.answer("n")
    term.expect(f"COULD-NOT-TEST  {MOVING_CASE} [GVE84-100]  -- safety stop: ")
    assert term.finish() == INCOMPLETE_STATUS
    assert "motion was not confirmed" in term.seen
    state = json.loads(unit.rig("state"))
    assert state["excursion"] == [[0, 0], [0, 0], [0, 0]]       # not one step, any axis
    last = term.seen.rstrip().splitlines()[-1]
    assert last == ("INCOMPLETE — 1 PASS; not tested: 1 of 2 (1 motion not confirmed)"), last
    folder = tmp_path / "declined"
    data = json.loads((folder / "results.json").read_text())
    assert data["verdict"] == "INCOMPLETE" and data["meta"]["confirmed"].startswith(
        "asked: refused")
    assert "class='banner INCOMPLETE'>INCOMPLETE<" in (folder / "report.html").read_text()
    for xml in (junit, folder / "junit.xml"):
        props = {p.get("name"): p.get("value") for p in ET.parse(xml).iter("property")}
        assert props["run verdict"].startswith("INCOMPLETE (1 PASS; not tested"), props


def _step(term: Terminal, step: str) -> None:
    """Wait for ``step``; the question before moving may come first (the first frame
    that can move an axis is sent when the case or its known state needs it)."""
    if term.expect_any(QUESTION, step) == QUESTION:
        term.answer("y")
        term.expect(step)


def test_hand_steps_done_are_verified(unit):
    term = _start(unit, HAND_CASE)
    for _ in ("G", "D", "K", "R"):
        _step(term, GROUND)
        unit.rig("in 1 FE")                          # the technician grounds IN0
        term.answer("")
        term.expect("verified: I1 = FE")
        _step(term, RELEASE)
        unit.rig("in 1 FF")
        term.answer("")
        term.expect("verified: I1 = FF")
    term.expect(f"PASS            {HAND_CASE} [GVE84-100]")
    assert term.finish() == 0 and "PASSED" in term.seen
    assert term.seen.count(QUESTION) == 1


def test_a_skipped_step_is_could_not_test_with_the_reason(unit):
    term = _start(unit, HAND_CASE)
    _step(term, GROUND)
    term.answer("s")
    term.expect(f"COULD-NOT-TEST  {HAND_CASE} [GVE84-100]  -- could not test: Ground input "
                "IN0 (the X reference input): skipped by the operator")
    assert term.finish() == INCOMPLETE_STATUS        # never a FAIL, nor a PASS


def test_a_wrong_action_is_caught_by_the_read_back(unit):
    term = _start(unit, HAND_CASE)
    _step(term, GROUND)
    unit.rig("in 1 FD")                              # IN1 grounded instead of IN0
    term.answer("")
    term.expect("not verified: I1 reads FD (IN0 should read 0); try again")
    term.expect(GROUND)                              # asked once more, then given up
    term.answer("")
    term.expect(f"COULD-NOT-TEST  {HAND_CASE} [GVE84-100]  -- could not test: Ground input "
                "IN0 (the X reference input): not verified, I1 reads FD (IN0 should read 0)")
    assert term.finish() == INCOMPLETE_STATUS


def test_yes_skips_the_question_and_no_operator_says_why(unit):
    term = Terminal(suite("--target", f"serial:{unit.path}", "--profile", "GVE84-100",
                          "--cases", HAND_CASE, "--cases", MOVING_CASE,
                          "--no-reports", "--yes", "--no-operator"))
    term.expect(f"PASS            {MOVING_CASE} [GVE84-100]")
    term.expect(f"COULD-NOT-TEST  {HAND_CASE} [GVE84-100]  -- could not test: needs a hand")
    assert term.finish() == INCOMPLETE_STATUS and QUESTION not in term.seen


def test_ctrl_c_at_the_question_stops_the_run_and_moves_nothing(unit):
    term = _start(unit, MOVING_CASE)
    _asked(term)
    term.proc.send_signal(signal.SIGINT)
    term.finish()
    assert "interrupted by Ctrl-C" in term.seen and "FAILED" in term.seen
    assert json.loads(unit.rig("state"))["excursion"] == [[0, 0], [0, 0], [0, 0]]


def test_the_rig_steps_by_hand_on_a_terminal(unit):
    """A real unit without a rig: the technician grounds an input, cycles the power and
    reads the outputs, each step read back; a case no hand can do says why."""
    term = Terminal(suite("--target", f"serial:{unit.path}", "--profile", "GVE84-100",
                          "--yes", "--allow-destructive", "--no-reports",
                          "--cases", "10.3.inputs.physical-across-restart",
                          "--cases", "10.cmd.output.port",
                          "--cases", "10.cmd.reference.to-switch"))
    term.expect("Ground input IN0 of port I1 now, then press Enter; s to skip:")
    unit.rig("in 1 FE")
    term.answer("")
    term.expect("verified: I1 = FE")
    term.expect("Cycle the unit's power")
    unit.rig("power-on")                             # the technician's power switch
    term.answer("")
    term.expect("verified: the index reads 0")
    term.expect("Release input IN0 of port I1 now")  # the hands off after the case
    unit.rig("in 1 FF")
    term.answer("")
    term.expect("PASS            10.3.inputs.physical-across-restart [GVE84-100]")
    for _ in range(2):                               # O0,FB: OUT2 lit, read twice
        term.expect("Which outputs are on now (lit)?")
        term.answer("2")
    term.expect("PASS            10.cmd.output.port [GVE84-100]")
    term.expect("COULD-NOT-TEST  10.cmd.reference.to-switch [GVE84-100]  -- needs a test "
                "rig: no hand can do it: a reference switch at an exact position")
    assert term.finish() == INCOMPLETE_STATUS
    assert term.seen.rstrip().splitlines()[-1] == (
        "INCOMPLETE — 2 PASS; not tested: 1 of 3 (1 need a rig no hand stands in for)")
