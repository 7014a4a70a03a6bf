"""What a rig's state does not give is not tested, never a failure of the unit: a rig
whose `state` has no `physical` leaves the check that reads it COULD-NOT-TEST, saying
so, and the checks that read what it does give still judge."""

from __future__ import annotations

from conformance.run.runner import run
from conformance.run.selection import select
from conformance.targets import parse_target
from conformance.verdicts.verdict import COULD_NOT_TEST, PASS
from emulator.link.line import Line

CASE = "10.4.halt.at-rest-on-the-rig"


def _run_case():
    (result,) = run([parse_target("emu:GVE84-100")], select([CASE])).results
    return result


def test_a_rig_with_eyes_judges_where_the_axes_stand():
    assert _run_case().verdict == PASS


def test_a_rig_without_physical_leaves_that_check_could_not_test(monkeypatch):
    state = Line.state

    def without_eyes(self, address=None):
        return {k: v for k, v in state(self, address).items() if k != "physical"}
    monkeypatch.setattr(Line, "state", without_eyes)
    result = _run_case()
    assert result.verdict == COULD_NOT_TEST
    assert "no 'physical'" in result.notes[0]
    # the counters the rig does give are still judged, and pass
    judged = {c["what"]: c["ok"] for c in result.checks}
    assert judged == {"from H's answer on, every axis's position stands still": True,
                      "PF reads the counters the rig reads": True}
    assert "None" not in " ".join(str(c["observed"]) for c in result.checks)
