"""SIGINT, SIGTERM or SIGHUP to a fleet's main process (what a CI's cancel or a closed
terminal sends it alone) at a drawn instant — the n-th frame one unit answers: on every
unit's line `H` comes at once, nothing that can move before it, then `D`; every member
halts its unit and writes its report, the summary says interrupted, exit status 130, no
traceback, and no process of the fleet is left."""

from __future__ import annotations

import json
import os
import random
import re
import signal
import subprocess
import sys
import time
from contextlib import ExitStack

import pytest

from tests.conformance.safety.proxy import unit_behind_proxy
from tests.processes import alive, descendants

pytestmark = pytest.mark.pty

#: frames the unit answers (after `*S` and a packet's members the suite does not wait)
ANSWERED = re.compile(rb"!0(?!\*S|C|B)")
#: frames that can start motion (the session's L0,0,0 polls and the *E-1 closer do not)
MOTION = re.compile(rb"!\d(L|C|G|W|\*E|SW6)")
#: how long the signal may take to reach a member and its H the line
HALT_SECONDS = 1.0


def assert_halted_first(frames: list[tuple[float, bytes]], signalled: float) -> None:
    """After the signal: `H` within HALT_SECONDS, nothing that can move before it, then
    `D`. The signal reaches a member through its parent: the frames a member sends in
    that millisecond or two are its known state's (never motion), and are allowed."""
    after = [(t, f) for t, f in frames if t > signalled]
    if not after:
        return                                   # that member had ended, or not begun
    halt = next((i for i, (_, f) in enumerate(after) if f[2:3] == b"H"), None)
    assert halt is not None, [f for _, f in after[:6]]
    assert after[halt][0] - signalled < HALT_SECONDS, after[:halt + 1]
    assert not [f for _, f in after[:halt] if MOTION.match(f)
                and not f.startswith((b"!0L0,0,0", b"!0*E-1\r"))], after[:halt]
    assert any(f[2:3] == b"D" for _, f in after[halt:]), after
CASES = ["--cases", "5.errors.*", "--cases", "8.index.*", "--cases", "10.4.*"]


@pytest.mark.parametrize("sig", [
    # SIGINT by default in test_cli_fleet.py: here in the slow runs
    pytest.param(signal.SIGINT, id="SIGINT", marks=pytest.mark.slow),
    pytest.param(signal.SIGTERM, id="SIGTERM"), pytest.param(signal.SIGHUP, id="SIGHUP")])
def test_a_signal_to_the_fleet_halts_every_unit_first(tmp_path, sig):
    nth = random.Random(f"fleet {sig}").randrange(20, 120)
    fleet: list[subprocess.Popen] = []
    signalled: list[float] = []
    started: list[int] = []
    answered: list[int] = []

    def on_frame(i: int, frame: bytes) -> None:
        if fleet and not signalled and ANSWERED.match(frame):
            answered.append(i)
            if len(answered) == nth:
                started.extend(descendants(fleet[0].pid))
                signalled.append(time.monotonic())
                os.kill(fleet[0].pid, sig)

    with ExitStack() as units:
        first = units.enter_context(unit_behind_proxy("--model", "GVE84-100",
                                                      on_frame=on_frame))[1]
        other = units.enter_context(unit_behind_proxy("--model", "GVE84-100"))[1]
        argv = [sys.executable, "-m", "conformance", "--target", f"serial:{first.path}",
                "--target", f"serial:{other.path}", "--profile", "GVE84-100", "--yes",
                "--max-travel", "500", "--jobs", "2", *CASES,
                "--report-dir", str(tmp_path), "--run-id", "fleet"]
        fleet.append(subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                      stdin=subprocess.DEVNULL))
        try:
            out = fleet[0].communicate(timeout=180)[0].decode(errors="replace")
        finally:
            if fleet[0].poll() is None:
                fleet[0].kill()
                fleet[0].wait()
    assert signalled, f"the {nth}th answered frame never came\n{out}"
    assert fleet[0].returncode == 130, out
    assert "Traceback" not in out, out
    for proxy in (first, other):
        assert_halted_first(proxy.frames, signalled[0])
    summary = json.loads((tmp_path / "fleet" / "summary.json").read_text())
    assert summary["interrupted"] and summary["verdict"] == "FAILED"
    for row in summary["targets"]:
        results = tmp_path / "fleet" / row["folder"] / "results.json"
        if row["exit_status"] == 130 and results.exists():
            assert json.loads(results.read_text())["interrupted"] is True
    assert len(started) >= 2, "both members were running"
    assert not any(alive(p) for p in started), "a process of the fleet was left running"
