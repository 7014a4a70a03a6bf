"""SIGINT, SIGTERM or SIGHUP to a fleet's main process (what a CI's cancel or a closed
terminal sends it alone) at a drawn instant — the n-th frame one unit answers: on every
unit's line `H` comes at once, nothing that can move before it, then `D`; every member
halts its unit and writes its report, the summary says interrupted, exit status 130, no
traceback, and no process of the fleet is left."""

from __future__ import annotations

import json
import random
import signal
import sys

import pytest

from tests.conformance.safety.signalling import assert_halted_first, signal_at_frame
from tests.processes import alive

pytestmark = pytest.mark.pty

CASES = ["--cases", "5.errors.*", "--cases", "8.index.*", "--cases", "10.4.*"]


@pytest.mark.parametrize("sig", [
    # SIGINT by default in test_cli_fleet.py: here in the slow runs
    pytest.param(signal.SIGINT, id="SIGINT", marks=pytest.mark.slow),
    pytest.param(signal.SIGTERM, id="SIGTERM"), pytest.param(signal.SIGHUP, id="SIGHUP")])
def test_a_signal_to_the_fleet_halts_every_unit_first(tmp_path, sig):
    nth = random.Random(f"fleet {sig}").randrange(20, 120)
    run = signal_at_frame(lambda first, other: [
        sys.executable, "-m", "conformance", "--target", f"serial:{first}",
        "--target", f"serial:{other}", "--profile", "GVE84-100", "--yes",
        "--max-travel", "500", "--jobs", "2", *CASES,
        "--report-dir", str(tmp_path), "--run-id", "fleet"], sig, nth)
    assert run.instant is not None, f"the {nth}th answered frame never came\n{run.out}"
    assert run.status == 130, run.out
    assert "Traceback" not in run.out, run.out
    for proxy in run.proxies:
        assert_halted_first(proxy.frames, run.instant)
    summary = json.loads((tmp_path / "fleet" / "summary.json").read_text())
    assert summary["interrupted"] and summary["verdict"] == "FAILED"
    for row in summary["targets"]:
        results = tmp_path / "fleet" / row["folder"] / "results.json"
        if row["exit_status"] == 130 and results.exists():
            assert json.loads(results.read_text())["interrupted"] is True
    assert len(run.started) >= 2, "both members were running"
    assert not any(alive(p) for p in run.started), "a process of the fleet was left running"
