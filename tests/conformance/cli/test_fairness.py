"""`gve-conformance fairness`: a reading is graded as any unit is (by the tags): its
differences NON-STRICT or INFO naming their rule, never FAIL; the strict reference
emulator FAILs the same difference; the score line."""

from __future__ import annotations

import random
import signal

import pytest

from conformance.catalogue import select
from conformance.cli import main
from conformance.runner import run_case
from conformance.targets import parse_target
from conformance.verdict import FAIL, NON_STRICT
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


def test_the_fairness_score_of_one_reading(capsys):
    status = main(["fairness", "--reading", "plus-sign", "--cases", "3.frame.*", "-v"])
    out = capsys.readouterr().out
    assert status == 0
    assert "fair    plus-sign" in out and "NON-STRICT 3.frame.syntax-errors [GVE84-100]" \
        " (3.params.decimal)" in out
    assert "fairness score: 1/1 = 100.0 %" in out


def test_an_unknown_reading_is_one_line_and_exit_2(capsys):
    assert main(["fairness", "--reading", "nosuch"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "unknown reading(s) nosuch" in err


def test_diff_runs_against_the_reading_and_names_the_rule_it_reads(capsys):
    """The unit counting @ and > differs from the reference in diff too: NON-STRICT under
    the counting rule on each profile, not a FAIL of the index (its first @ is where the
    index is compared from)."""
    status = main(["fairness", "--reading", "queries-counted", "--cases", "8.index.*"])
    out = capsys.readouterr().out
    assert status == 0, out
    for profile in ("GVE84-100", "GVE54", "GVE114-500"):
        line = next(x for x in out.splitlines() if x.strip().startswith(f"diff {profile}:"))
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
    argv = ["fairness", "--jobs", "2", "--reading", "plus-sign", "--reading", "queries-counted"]
    status, out, started = signalled(argv, sig, group=group, delay=delay,
                                     ready=lambda pid: len(descendants(pid)) >= 2)
    assert status == 130, out
    assert "Traceback" not in out, out
    assert out.splitlines()[-1].startswith("fairness: interrupted by a signal after "), out
    assert len(started) >= 2 and not any(alive(p) for p in started)
