"""`gve-conformance host`: bad usage gets one line on stderr and exit status 2."""

from __future__ import annotations

import json
import os
import select
import signal
import subprocess
import sys
import time
from pathlib import Path

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
    (["host", "--profile", "GVE84-100", "--clean-limit", "0", *HOST], "--clean-limit"),
    (["host", "--profile", "GVE84-100", "--reading", "index-hx", *HOST], "index-hx"),
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


def running(pid: int) -> bool:
    """Whether ``pid`` is a live process (a zombie waiting for PID 1 to reap it is not)."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except FileNotFoundError:
        return False
    return stat.rsplit(")", 1)[1].split()[0] != "Z"


@pytest.mark.pty
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM, signal.SIGHUP],
                         ids=["SIGINT", "SIGTERM", "SIGHUP"])
def test_a_signal_stops_every_host_and_writes_the_reports(tmp_path, sig):
    """A signal while the host runs (one that ignores SIGTERM and starts a child): the
    host's whole process group is gone, the reports are written with the interrupted
    scenario, and the exit status is 1, within a few seconds."""
    fifo = tmp_path / "started"
    os.mkfifo(fifo)
    host = tmp_path / "host.sh"
    host.write_text(f"#!/bin/sh\ntrap '' TERM\nsleep 60 &\necho $$ $! > {fifo}\nwait\n")
    host.chmod(0o755)
    reader = os.open(fifo, os.O_RDONLY | os.O_NONBLOCK)
    proc = subprocess.Popen(
        [sys.executable, "-m", "conformance", "host", "--profile", "GVE84-100",
         "--report-dir", str(tmp_path / "reports"), "--host-timeout", "30", "--",
         str(host), "{port}"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        assert select.select([reader], [], [], 20)[0], "the host never started"
        pids = [int(p) for p in os.read(reader, 100).split()]
    finally:
        os.close(reader)
    signalled = time.monotonic()
    proc.send_signal(sig)
    out, _ = proc.communicate(timeout=30)
    assert time.monotonic() - signalled < 10
    assert proc.returncode == 130 and "interrupted" in out and "Traceback" not in out, out
    assert not [pid for pid in pids if running(pid)], "the host or its child is still there"
    (folder,) = (tmp_path / "reports").iterdir()
    report = json.loads((folder / "results.json").read_text())
    assert report["interrupted"] is True
    assert [r["id"] for r in report["results"] if r["interrupted"]] == ["2.host.clean"]
