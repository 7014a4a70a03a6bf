"""`gve-conformance mutation` stopped by SIGINT, SIGTERM or SIGHUP — to its main process
or, as a terminal's Ctrl-C, to its whole process group — at a drawn instant while its
workers hunt: every worker ends, the one last line says it was interrupted, exit status
130, no traceback."""

from __future__ import annotations

import random
import signal

import pytest

from tests.processes import alive, descendants, signalled

#: a sweep of the catalogue against a few mutants: long enough to be stopped in
SWEEP = ["mutation", "--jobs", "2", "--sweep", "--profile", "GVE84-100",
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
    assert out.splitlines()[-1].startswith("mutation: interrupted by a signal after "), out
    assert len(started) >= 2 and not any(alive(p) for p in started)
