"""The suite under pytest-xdist stopped by SIGINT, SIGTERM or SIGHUP to pytest's main
process (the controller, alone: what a CI's cancel sends) at a drawn instant: every
worker's unit gets `H` at once, nothing that moves before it; the item in flight is
COULD-NOT-TEST, no other item starts; the units are put back, the JUnit file is written,
pytest ends as an interrupted run (exit status 2), no traceback, no worker left."""

from __future__ import annotations

import os
import random
import re
import signal
import subprocess
import sys
import time
import xml.etree.ElementTree as ET
from contextlib import ExitStack

import pytest

from tests.conformance.fleet.test_fleet_signals import ANSWERED, assert_halted_first
from tests.conformance.safety.proxy import unit_behind_proxy
from tests.processes import alive, descendants

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
    pytest_proc: list[subprocess.Popen] = []
    signalled: list[float] = []
    started: list[int] = []
    answered: list[int] = []

    def on_frame(i: int, frame: bytes) -> None:
        if pytest_proc and not signalled and ANSWERED.match(frame):
            answered.append(i)
            if len(answered) == nth:
                started.extend(descendants(pytest_proc[0].pid))
                signalled.append(time.monotonic())
                os.kill(pytest_proc[0].pid, sig)

    junit = tmp_path / "junit.xml"
    with ExitStack() as units:
        first = units.enter_context(unit_behind_proxy("--model", "GVE84-100",
                                                      on_frame=on_frame))[1]
        other = units.enter_context(unit_behind_proxy("--model", "GVE84-100"))[1]
        argv = [sys.executable, "-m", "pytest", "-p", "no:cacheprovider", "-n", workers, "-q",
                "--gve-profile", "GVE84-100", "--gve-max-travel", "500",
                "--gve-target", f"serial:{first.path}", "--gve-target", f"serial:{other.path}",
                *CASES, "--junitxml", str(junit)]
        pytest_proc.append(subprocess.Popen(argv, cwd=tmp_path, stdout=subprocess.PIPE,
                                            stderr=subprocess.STDOUT,
                                            stdin=subprocess.DEVNULL))
        try:
            out = pytest_proc[0].communicate(timeout=300)[0].decode(errors="replace")
        finally:
            if pytest_proc[0].poll() is None:
                pytest_proc[0].kill()
                pytest_proc[0].wait()
    assert signalled, f"the {nth}th answered frame never came\n{out}"
    assert pytest_proc[0].returncode == pytest.ExitCode.INTERRUPTED, out
    assert "Traceback" not in out and "crashed" not in out, out
    assert re.search(r"Interrupted: interrupted by a signal", out), out
    for proxy in (first, other):
        assert_halted_first(proxy.frames, signalled[0])
    skipped = [s.get("message", "") for s in ET.parse(junit).getroot().iter("skipped")]
    assert any("interrupted by a signal" in m for m in skipped), skipped
    assert workers == "0" or len(started) >= 2, "both workers were running"
    assert not any(alive(p) for p in started)
