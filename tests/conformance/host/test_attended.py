"""Attended mode, driven as an operator would: the port is printed first, then for each
scenario an instruction; the "operator" runs the host and types how its job ended."""

from __future__ import annotations

import json
import queue
import subprocess
import sys
import threading

import pytest

from tests.conformance.host.run import JOB

pytestmark = pytest.mark.pty


class Console:
    """The lines the program prints, as they come (a thread reads them)."""

    def __init__(self, proc: subprocess.Popen) -> None:
        self.lines: queue.Queue[str] = queue.Queue()
        threading.Thread(target=self._read, args=(proc,), daemon=True).start()

    def _read(self, proc: subprocess.Popen) -> None:
        for line in proc.stdout:
            self.lines.put(line)

    def readline(self, timeout: float = 30.0) -> str:
        try:
            return self.lines.get(timeout=timeout)
        except queue.Empty:
            raise AssertionError("gve-conformance host printed nothing") from None


def test_an_operator_runs_the_host_for_each_scenario(tmp_path):
    proc = subprocess.Popen(
        [sys.executable, "-m", "conformance", "host", "--profile", "GVE84-100",
         "--scenarios", "lost-answer.vector", "--report-dir", str(tmp_path)],
        stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        bufsize=1)
    console = Console(proc)
    readline = console.readline
    try:
        first = readline()
        assert first.startswith("port: /dev/")
        port = first.split(": ", 1)[1].strip()
        for said in ("done", "done"):
            line = readline()
            assert line.startswith("["), line            # "[1/2] 2.host.clean: ..."
            assert port in readline()                 # "Start the host's job on ..."
            host = subprocess.run([sys.executable, "-m", "gve_host", port, "--job", str(JOB)],
                                  timeout=60, capture_output=True)
            assert host.returncode == 0, host.stderr
            proc.stdin.write(said + "\n")
            proc.stdin.flush()
            assert readline().startswith("PASS")
        proc.stdin.close()
        proc.wait(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 0, proc.stderr.read()
    (folder,) = tmp_path.iterdir()
    results = json.loads((folder / "results.json").read_text())["results"]
    assert [r["verdict"] for r in results] == ["PASS", "PASS"]
    assert all(r["ended"] == "operator" and r["exit_code"] == 0 for r in results)
