"""Attended mode, driven as an operator would at a terminal: the port is printed first,
then for each scenario an instruction; the "operator" runs the host and types how its
job ended. Without a terminal nobody can say it: the certification stops before it
starts, as the suite's run does."""

from __future__ import annotations

import io
import json
import re
import subprocess
import sys

import pytest

from conformance.cli import main
from tests.conformance.host.run import JOB
from tests.conformance.operator.terminal import Terminal

pytestmark = pytest.mark.pty


def test_an_operator_runs_the_host_for_each_scenario(tmp_path):
    term = Terminal([sys.executable, "-m", "conformance", "host", "--profile", "GVE84-100",
                     "--scenarios", "lost-answer.vector", "--report-dir", str(tmp_path)])
    try:
        term.expect("port: ")
        port = term.expect("\n").strip()
        assert port.startswith("/dev/")
        for said in ("done", "done"):
            assert re.search(r"\[\d/2\]", term.expect(port))   # "[1/2] 2.host.clean: ..."
            host = subprocess.run([sys.executable, "-m", "gve_host", port, "--job", str(JOB)],
                                  timeout=60, capture_output=True)
            assert host.returncode == 0, host.stderr
            term.answer(said)
            term.expect("PASS")
        status = term.finish()
    finally:
        if term.proc.poll() is None:
            term.proc.kill()
            term.proc.wait()
    assert status == 0, term.seen[-2000:]
    (folder,) = tmp_path.iterdir()
    results = json.loads((folder / "results.json").read_text())["results"]
    assert [r["verdict"] for r in results] == ["PASS", "PASS"]
    assert all(r["ended"] == "operator" and r["exit_code"] == 0 for r in results)


def test_without_a_terminal_attended_mode_stops_before_it_starts(tmp_path, capsys,
                                                                  monkeypatch):
    monkeypatch.setattr(sys, "stdin", io.StringIO())           # a CI job: no terminal
    assert main(["host", "--profile", "GVE84-100", "--report-dir", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and "terminal" in err and "--" in err
    assert not any(tmp_path.iterdir())                           # nothing ran
