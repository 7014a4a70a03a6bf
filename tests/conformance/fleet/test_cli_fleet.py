"""``gve-conformance --target A --target B --jobs N``: targets in
parallel processes, one report per target and a summary across them; an interrupt halts
every target's unit (H, then D) and still reports."""

from __future__ import annotations

import json
import os
import re
import selectors
import signal
import subprocess
import sys
import time
import xml.etree.ElementTree as ET

from conformance.cli import main
from conformance.cli.fleet import labels

MUTANT = "emu:GVE84-100?mutant=go-without-inta"     # 5.errors.go-without-inta FAILs it


def test_targets_run_in_parallel_with_a_report_each_and_a_summary(tmp_path, capsys):
    junit = tmp_path / "ci" / "junit.xml"
    status = main(["--target", "emu:GVE54", "--target", MUTANT, "--jobs", "2",
                   "--cases", "5.errors.*", "--report-dir", str(tmp_path / "reports"),
                   "--run-id", "fleet", "--junitxml", str(junit)])
    out = capsys.readouterr().out
    assert status == 1                                # one target FAILs
    folder = tmp_path / "reports" / "fleet"
    summary = json.loads((folder / "summary.json").read_text())
    rows = {row["target"]: row for row in summary["targets"]}
    assert rows["emu:GVE54"]["verdict"] == "PASSED"
    assert rows[MUTANT]["verdict"] == "FAILED" and rows[MUTANT]["counts"]["FAIL"] == 1
    assert summary["verdict"] == "FAILED" and summary["reason"] == "1 of 2 targets failed"
    # the two processes overlapped in time
    assert max(r["started"] for r in rows.values()) < min(r["ended"] for r in rows.values())
    for row in rows.values():
        names = {p.name for p in (folder / row["folder"]).iterdir()}
        assert {"report.html", "results.json", "junit.xml"} <= names
        assert f'href="{row["folder"]}/report.html"' in (folder / "index.html").read_text()
        # each target's output, line by line behind its name
        assert f"[{row['folder']}] " in out
    suites = ET.parse(junit).getroot().findall("testsuite")
    assert sorted(s.get("name") for s in suites) == sorted(rows)
    assert out.rstrip().splitlines()[-1] == "FAILED — 1 of 2 targets failed"


def test_jobs_must_be_one_or_more(capsys):
    assert main(["--target", "emu:GVE54", "--jobs", "0", "--no-reports"]) == 2
    assert "--jobs" in capsys.readouterr().err


def test_target_folders_are_safe_and_distinct():
    names = labels(["tcp:127.0.0.1:5114", "serial:/dev/ttyUSB0?baud=9600",
                    "tcp:127.0.0.1/5114", "emu:GVE54"])
    assert names[0] == "tcp-127.0.0.1-5114" and names[3] == "emu-GVE54"
    assert len(set(names)) == 4 and all("/" not in n and "?" not in n for n in names)


def test_an_interrupt_halts_every_unit_and_still_reports(tcp_units, tmp_path):
    """SIGINT to the fleet alone (as a CI's cancel sends it): every target gets one,
    sends H and D to its unit, and writes its report; the fleet reports interrupted."""
    logs = [tmp_path / "unit-a.gvt", tmp_path / "unit-b.gvt"]
    ports = [tcp_units("--model", "GVE84-100", "--log", str(log)) for log in logs]
    argv = [sys.executable, "-m", "conformance", "--profile", "GVE84-100", "--yes", "--jobs", "2",
            "--cases", "10.*", "--report-dir", str(tmp_path), "--run-id", "fleet"]
    for where in ports:
        argv += ["--target", f"tcp:{where}"]
    fleet = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                             text=True)
    try:
        # both targets have judged cases: both units are in the middle of the run (a log
        # shows a line for what did not PASS and one at every tenth of the way)
        started: set[str] = set()
        for line in _lines(fleet, deadline=120):
            if re.match(r"\[\S+\] \[ *\d+/\d+\]", line):    # "[tcp-...] [7/64] 10 % in 2.1 s"
                started.add(line.split("]")[0])
            if len(started) == 2:
                break
        assert len(started) == 2, "the targets did not start"
        os.kill(fleet.pid, signal.SIGINT)
        rest = "".join(_lines(fleet, deadline=60))
        assert fleet.wait(10) == 130, rest
    finally:
        if fleet.poll() is None:
            fleet.kill()
            fleet.wait()
    summary = json.loads((tmp_path / "fleet" / "summary.json").read_text())
    assert summary["interrupted"] and summary["verdict"] == "FAILED"
    assert all(row["interrupted"] for row in summary["targets"])
    for log in logs:
        sent = [line.split(" > ")[1] for line in log.read_text().splitlines() if " > " in line]
        # the emergency stop: H, then D at once (the known state puts frames between them);
        # the session's restorations follow
        assert any(sent[i:i + 2] == ["!0H\\r", "!0D\\r"] for i in range(len(sent))), sent[-9:]


def _lines(process: subprocess.Popen, deadline: float):
    """The process's output lines until it ends or ``deadline`` seconds have passed."""
    end = time.monotonic() + deadline
    sel = selectors.DefaultSelector()
    sel.register(process.stdout, selectors.EVENT_READ)
    while time.monotonic() < end and sel.select(end - time.monotonic()):
        line = process.stdout.readline()
        if not line:
            return
        yield line
