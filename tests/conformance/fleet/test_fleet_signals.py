"""SIGINT, SIGTERM or SIGHUP to a fleet's main process (what a CI's cancel or a closed
terminal sends it alone) at a drawn instant — the n-th frame one unit answers: the next
frame on that unit's line is `H`, on every other unit's line after at most the one frame
already on it; every member halts its unit and writes its report, the summary says
interrupted, exit status 130, no traceback, and no process of the fleet is left."""

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
CASES = ["--cases", "5.errors.*", "--cases", "8.index.*", "--cases", "10.4.*"]


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM, signal.SIGHUP],
                         ids=["SIGINT", "SIGTERM", "SIGHUP"])
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
    # the unit whose frame was in flight: H next; the other: at most its frame in flight
    for proxy, in_flight in ((first, 0), (other, 1)):
        after = [f[2:-1] for t, f in proxy.frames if t > signalled[0]]
        if after:
            assert b"H" in after[:in_flight + 1], after[:4]
            assert b"D" in after, after
    summary = json.loads((tmp_path / "fleet" / "summary.json").read_text())
    assert summary["interrupted"] and summary["verdict"] == "FAILED"
    for row in summary["targets"]:
        results = tmp_path / "fleet" / row["folder"] / "results.json"
        if row["exit_status"] == 130 and results.exists():
            assert json.loads(results.read_text())["interrupted"] is True
    assert len(started) >= 2, "both members were running"
    assert not any(alive(p) for p in started), "a process of the fleet was left running"
