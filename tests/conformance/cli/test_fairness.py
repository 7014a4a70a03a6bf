"""`gve-conformance fairness`: a reading is graded as any unit is (by the tags): its
differences NON-STRICT or INFO naming their rule, never FAIL; the strict reference
emulator FAILs the same difference; the score line."""

from __future__ import annotations

import random
import re
import signal

import pytest

from conformance.cli import main
from conformance.run.runner import run_case
from conformance.run.selection import select
from conformance.targets import parse_target
from conformance.targets.emu import emulator_readings
from conformance.verdicts.verdict import FAIL, NON_STRICT
from tests.conformance.cli.test_gate import _testcases
from tests.conformance.cli.test_progress import _steps
from tests.processes import alive, descendants, signalled


def test_an_emulator_taking_a_reading_is_graded_by_the_tags():
    (case,) = select(["3.frame.syntax-errors"])
    read = parse_target("emu:GVE84-100?reading=plus-sign")
    assert not read.info.strict
    r = run_case(case, read)
    assert r.verdict == NON_STRICT
    assert {c["rule"] for c in r.checks if not c["ok"]} == {"3.params.decimal"}
    # the same unit claiming our decisions (--strict) FAILs it
    strict = parse_target("emu:GVE84-100?reading=plus-sign", strict=True)
    assert run_case(case, strict).verdict == FAIL


def test_the_fairness_score_junit_and_log_of_one_reading(tmp_path, capsys,
                                                         fairness_on_one_profile):
    """One reading tried (one trial, a few seconds: its score line, its JUnit testcase and
    its numbered log line are read off the one run)."""
    junit = tmp_path / "f.xml"
    status = main(["fairness", "--no-reports", "--reading", "plus-sign",
                   "--cases", "3.frame.*", "-v", "--junitxml", str(junit)])
    out = capsys.readouterr().out
    assert status == 0
    assert "fair    plus-sign" in out and "NON-STRICT 3.frame.syntax-errors [GVE84-100]" \
        " (3.params.decimal)" in out
    assert out.strip().splitlines()[-1].startswith("PASSED — fairness score: 1/1 = 100.0 %")
    (case,) = _testcases(junit).values()
    assert case.get("name") == "plus-sign" and case.find("failure") is None
    # (lines saying it is still working, every 5 s, count nothing done)
    (step,) = [s for s in _steps(out) if s[0] > 0]
    assert step[:2] == (1, 1) and "plus-sign" in step[2]


def test_an_unknown_reading_is_one_line_and_exit_2(capsys):
    assert main(["fairness", "--no-reports", "--reading", "nosuch"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "unknown reading(s) nosuch" in err


def test_diff_runs_against_the_reading_and_names_the_rule_it_reads(capsys,
                                                                   fairness_on_one_profile):
    """The unit counting @ and > differs from the reference in diff too: NON-STRICT under
    the counting rule, not a FAIL of the index (its first @ is where the index is compared
    from). (On every family: the fairness gate, one profile of each.)"""
    status = main(["fairness", "--no-reports",
                   "--reading", "queries-counted", "--cases", "8.index.*"])
    out = capsys.readouterr().out
    assert status == 0, out
    line = next(x for x in out.splitlines()
                if x.strip().startswith(f"diff {fairness_on_one_profile}:"))
    assert "NON-STRICT 8.index.queries-uncounted" in line and "FAIL" not in \
        line.replace("NON-STRICT", ""), line
    assert "fairness score: 1/1 = 100.0 %" in out


@pytest.mark.parametrize(("sig", "group"), [(signal.SIGINT, True), (signal.SIGTERM, False),
                                            (signal.SIGHUP, False)],
                         ids=["SIGINT-to-the-group", "SIGTERM", "SIGHUP"])
def test_a_signal_stops_every_worker_with_one_line(sig, group):
    """SIGINT (to the process group, as a terminal sends it), SIGTERM or SIGHUP at a
    drawn instant while two readings are tried: the workers end, one last line, 130."""
    delay = random.Random(f"fairness {sig}").uniform(0.0, 1.5)
    argv = ["fairness", "--no-reports",
            "--jobs", "2", "--reading", "plus-sign", "--reading", "queries-counted"]
    status, out, started = signalled(argv, sig, group=group, delay=delay,
                                     ready=lambda pid: len(descendants(pid)) >= 2)
    assert status == 130, out
    assert "Traceback" not in out, out
    last = out.splitlines()[-1]
    assert last.startswith("FAILED — fairness interrupted by a signal after "), out
    # the readings it was trying count too, not only those it finished
    assert re.search(r"\d of 2 readings finished \(\d unfair; \d under way\)", last), last
    assert len(started) >= 2 and not any(alive(p) for p in started)


def test_a_reading_alone_is_tried_where_the_rules_it_reads_apply():
    from conformance.cli.fairness import FIRST, trial_profiles
    assert trial_profiles(("7.packet.codes",), list(FIRST)) == ["GVE84-100", "GVE114-500"]
    assert trial_profiles(("9.reset.mpg-parameters",), list(FIRST)) == ["GVE114-500"]
    assert trial_profiles(("3.frame.upper-case",), list(FIRST)) == list(FIRST)


def test_a_check_that_names_no_rule_makes_a_reading_unfair(monkeypatch):
    from conformance.cli import fairness
    from conformance.run.runner import CaseResult

    def unnamed(case, target, settings=None):
        return CaseResult(case.id, case.section, case.rule, case.tag, case.source,
                          target.profile.name, target.info.spec, "PASS",
                          checks=[{"ok": True, "what": "x", "observed": "", "expected": "",
                                   "tag": "M", "rule": ""}])
    monkeypatch.setattr("conformance.run.runner.run_case", unnamed)
    monkeypatch.setattr(fairness, "diff_trial", lambda *a: None)
    t = fairness.trial("plus-sign", ["plus-sign"], ["GVE84-100"], ["1.profile.version"])
    assert not t.fair and "names no rule" in t.unfair[0]


def test_fairness_runs_diff_and_names_the_rule_of_every_difference(capsys,
                                                                   fairness_on_one_profile):
    # the reference's R with nothing kept answered 5: the empty save's rule, as the
    # catalogue grades it, not the exact restore's [M]
    status = main(["fairness", "--no-reports", "--reading", "restore-nothing-kept-range",
                   "--cases", "10.5.restore.*"])
    out = capsys.readouterr().out
    assert status == 0, out
    assert "NON-STRICT 10.5.restore.pops" in out and "FAIL" not in out.replace("NON-STRICT", "")


@pytest.mark.slow
@pytest.mark.parametrize("reading", sorted(emulator_readings()))
def test_every_reading_alone_is_fair_and_every_check_names_its_rule(reading):
    from conformance.cli.fairness import FIRST, trial, trial_profiles
    profiles = trial_profiles(emulator_readings()[reading][0], list(FIRST))
    t = trial(reading, [reading], profiles, None)
    assert t.fair, t.unfair
