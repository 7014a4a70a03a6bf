"""The suite under pytest-xdist stopped by SIGINT, SIGTERM or SIGHUP to pytest's main
process (the controller, alone: what a CI's cancel sends) at a drawn instant: every
worker's unit gets `H` at once, nothing that moves before it; the item in flight is
COULD-NOT-TEST, no other item starts; the units are put back, the JUnit file is written,
pytest ends as an interrupted run (exit status 2), no traceback, no worker left."""

from __future__ import annotations

import random
import signal
import sys
import xml.etree.ElementTree as ET

import pytest

from tests.conformance.safety.signalling import assert_halted_first, signal_at_frame
from tests.processes import alive

pytestmark = pytest.mark.pty
pytest.importorskip("xdist", reason="pytest-xdist (the dev extra) runs the workers")

CASES = ["--gve-cases", "5.errors.*", "--gve-cases", "8.index.*", "--gve-cases", "10.4.*"]


@pytest.mark.parametrize(("sig", "workers"), [
    pytest.param(signal.SIGINT, "2", id="SIGINT", marks=pytest.mark.slow),
    pytest.param(signal.SIGTERM, "2", id="SIGTERM"),
    pytest.param(signal.SIGHUP, "2", id="SIGHUP", marks=pytest.mark.slow),
    pytest.param(signal.SIGTERM, "0", id="SIGTERM-without-xdist")])
def test_a_signal_to_the_controller_halts_every_worker_s_unit(tmp_path, sig, workers):
    """(``-n 0``: pytest alone, the same signal to the one process that runs the items.)"""
    nth = random.Random(f"xdist {sig} {workers}").randrange(20, 80)
    junit = tmp_path / "junit.xml"
    run = signal_at_frame(lambda first, other: [
        sys.executable, "-m", "pytest", "-p", "no:cacheprovider", "-n", workers, "-q",
        "--gve-profile", "GVE84-100", "--gve-max-travel", "500", "--gve-yes",
        "--gve-target", f"serial:{first}", "--gve-target", f"serial:{other}", *CASES,
        "--junitxml", str(junit)], sig, nth, cwd=str(tmp_path))
    assert run.instant is not None, f"the {nth}th answered frame never came\n{run.out}"
    assert run.status == pytest.ExitCode.INTERRUPTED, run.out
    assert "Traceback" not in run.out and "crashed" not in run.out, run.out
    assert "Interrupted: interrupted by a signal" in run.out, run.out
    for proxy in run.proxies:
        assert_halted_first(proxy.frames, run.instant)
    skipped = [s.get("message", "") for s in ET.parse(junit).getroot().iter("skipped")]
    # the item in flight, where the signal came inside one (on a loaded machine it may
    # come on the session's own frames between two items), is COULD-NOT-TEST saying so
    assert any("interrupted" in m for m in skipped), skipped
    assert all("H and D sent" in m for m in skipped if "interrupted by Ctrl-C" in m), skipped
    assert workers == "0" or len(run.started) >= 2, "both workers were running"
    assert not any(alive(p) for p in run.started)
