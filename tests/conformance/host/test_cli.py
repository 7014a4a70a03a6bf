"""`gve-conformance host`: bad usage gets one line on stderr and exit status 2."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

import pytest

from conformance.cli import main

HOST = ["--", "python", "-m", "gve_host", "{port}", "--job", "x.job"]


@pytest.mark.parametrize(("argv", "says"), [
    (["host", *HOST], "--profile"),
    (["host", "--profile", "GVE99", *HOST], "GVE99"),
    (["host", "--profile", "GVE84-100", "--baud", "9600", *HOST], "9600"),
    (["host", "--profile", "GVE84-100", "--", "python", "-m", "gve_host"], "{port}"),
    (["host", "--profile", "GVE84-100", "--scenarios", "no-such", *HOST], "no-such"),
    (["host", "--profile", "GVE84-100", "--unit", "GVE54@1", *HOST], "--profile"),
    (["host", "--unit", "GVE54@9", *HOST], "0..7"),
    (["host", "--profile", "GVE84-100", "--bogus", *HOST], "--bogus"),
    (["host", "--profile", "GVE84-100", "--host-timeout", "0", *HOST], "--host-timeout"),
])
def test_usage_errors(capsys, argv, says):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert says in err and len(err.strip().splitlines()) == 1 and "Traceback" not in err


def test_a_host_program_that_does_not_exist(capsys, tmp_path):
    argv = ["host", "--profile", "GVE84-100", "--no-reports", "--",
            str(tmp_path / "no-such-host"), "{port}"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "no-such-host" in err and len(err.strip().splitlines()) == 1


def test_the_scenario_list(capsys):
    assert main(["host", "--list"]) == 0
    out = capsys.readouterr().out
    assert "2.host.clean" in out and "8.host.lost-answer.vector" in out


@pytest.mark.pty
def test_ctrl_c_stops_every_host_and_says_so(tmp_path):
    """SIGINT while hosts run: they are stopped, what finished is reported, exit 1."""
    pids = tmp_path / "pids"
    host = tmp_path / "host.sh"          # a host that never ends, and says who it is
    host.write_text(f"#!/bin/sh\necho $$ >> {pids}\nexec sleep 60\n")
    host.chmod(0o755)
    proc = subprocess.Popen(
        [sys.executable, "-m", "conformance", "host", "--profile", "GVE84-100",
         "--no-reports", "--host-timeout", "30", "--", str(host), "{port}"],
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    deadline = time.monotonic() + 20
    while not (pids.exists() and pids.read_text().strip()) and time.monotonic() < deadline:
        time.sleep(0.05)               # wait for the host to have started
    proc.send_signal(signal.SIGINT)
    out, _ = proc.communicate(timeout=30)
    assert proc.returncode == 1 and "interrupted by Ctrl-C" in out and "Traceback" not in out
    for pid in map(int, pids.read_text().split()):
        with pytest.raises(ProcessLookupError):
            os.kill(pid, 0)              # the host is gone
