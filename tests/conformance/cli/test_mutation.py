"""`gve-conformance mutation --sweep`: a case runs against a mutant only where its clean
run reached the mutant's code, and what it leaves out it says; the catch is the one the
whole sweep makes. Stopped by SIGINT, SIGTERM or SIGHUP — to its main process or, as a
terminal's Ctrl-C, to its whole process group — at a drawn instant while its workers
hunt: every worker ends, the one last line says it was interrupted, exit status 130, no
traceback."""

from __future__ import annotations

import random
import re
import signal

import pytest

from conformance.cli.mutation import clean_run, hunt, main
from conformance.run.selection import select
from conformance.targets import parse_target
from tests.processes import alive, descendants, signalled


def test_the_sweep_leaves_out_the_cases_that_never_reach_the_mutant(capsys):
    args = ["--mutant", "sw6-inert", "--profile", "GVE84-100", "--cases", "10.3.*"]
    assert main([*args, "--sweep", "--no-reports"]) == 0
    out = capsys.readouterr().out
    assert "caught  sw6-inert" in out
    (left_out,) = re.findall(r"(\d+) not run, the mutant's code unreached", out)
    clean = parse_target("emu:GVE84-100")
    cases = [c for c in select(["10.3.*"]) if not c.missing_for(clean.profile)]
    unreached = [c for c in cases if "sw6-inert" not in clean_run(c, clean)[1]]
    assert int(left_out) == len(unreached) > 0
    # the hunt without the sweep runs every case until the catch, and catches it alike
    assert hunt("sw6-inert", ["GVE84-100"], ["10.3.*"]).caught_by == \
        hunt("sw6-inert", ["GVE84-100"], ["10.3.*"], sweep=True).caught_by


#: a sweep of the catalogue against a few mutants: long enough to be stopped in
SWEEP = ["mutation", "--no-reports", "--jobs", "2", "--sweep", "--profile", "GVE84-100",
         "--mutant", "go-without-inta", "--mutant", "sw6-inert", "--mutant", "velocity-ignored"]


def two_workers(pid: int) -> bool:
    return len(descendants(pid)) >= 2


@pytest.mark.parametrize(("sig", "group"), [(signal.SIGINT, True), (signal.SIGTERM, False),
                                            (signal.SIGHUP, False)],
                         ids=["SIGINT-to-the-group", "SIGTERM", "SIGHUP"])
def test_a_signal_stops_every_worker_with_one_line(sig, group):
    delay = random.Random(f"mutation {sig}").uniform(0.0, 1.5)
    status, out, started = signalled(SWEEP, sig, ready=two_workers, delay=delay,
                                     group=group)
    assert status == 130, out
    assert "Traceback" not in out, out
    assert out.splitlines()[-1].startswith("FAILED — mutation interrupted by a signal after "), out
    assert len(started) >= 2 and not any(alive(p) for p in started)
