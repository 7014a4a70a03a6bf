"""A certified host drives its units (2.link.host-drives): one that sends nothing, or
stops half-way and exits 0, FAILs; the console ends with the verdict line; the report's
metadata shows the host command and the certification's options."""

from __future__ import annotations

import json
import shutil
import sys
from pathlib import Path

import pytest

from conformance.cli.host import main
from conformance.verdicts.verdict import FAIL, PASS
from tests.conformance.host.run import HOST_TIMEOUT, certify, failing_rules

pytestmark = pytest.mark.pty

HERE = Path(__file__).parent
SHELL = str(HERE / "shell_host.sh")
HALF = [sys.executable, str(HERE / "half_host.py"), "{port}"]
#: the shell host's job travels X 1000, Y 500 full steps
SHELL_MOTION = "1000,500,0"


def _last_line(capsys) -> str:
    return capsys.readouterr().out.rstrip().splitlines()[-1]


def test_a_host_that_sends_nothing_fails(tmp_path, capsys):
    status = main(["--profile", "GVE84-100", "--report-dir", str(tmp_path), "--", "true",
                   "{port}"])
    last = _last_line(capsys)
    assert status == 1
    (folder,) = [p for p in tmp_path.iterdir() if p.is_dir()]
    results = json.loads((folder / "results.json").read_text())["results"]
    clean = next(r for r in results if r["scenario"] == "clean")
    assert clean["verdict"] == FAIL and failing_rules(clean) == {"2.link.host-drives"}
    assert last.startswith("FAILED — 1 FAIL; not tested: 17 of 18 ("), last


def test_a_host_that_stops_half_way_and_exits_0_fails(tmp_path, capsys):
    status, results = certify(tmp_path, "GVE84-100", command=HALF, scenarios=("clean",),
                              options=("--expect-motion", SHELL_MOTION))
    (clean,) = results
    assert status == 1 and clean["verdict"] == FAIL
    assert failing_rules(clean) == {"2.link.host-drives"}
    (check,) = [c for c in clean["checks"] if not c["ok"]]
    assert check["observed"] == "it travelled X 500, Y 0, Z 0 full steps", check
    assert _last_line(capsys) == "FAILED — 1 FAIL; everything tested (1)"


@pytest.mark.skipif(shutil.which("bash") is None or shutil.which("stty") is None,
                    reason="needs bash and stty")
def test_the_whole_job_executed_passes_with_the_verdict_line_and_metadata(tmp_path, capsys):
    status, results = certify(tmp_path, "GVE84-100", command=[SHELL, "{port}"],
                              scenarios=("clean",), options=("--expect-motion", SHELL_MOTION))
    (clean,) = results
    assert status == 0 and clean["verdict"] == PASS, clean
    assert "2.link.host-drives" in clean["rules_judged"]
    assert _last_line(capsys) == "PASSED — 1 PASS; everything tested (1)"
    (folder,) = [p for p in tmp_path.iterdir() if p.is_dir()]
    meta = json.loads((folder / "results.json").read_text())["meta"]
    assert meta["host_command"] == [SHELL, "{port}"]
    assert meta["command"][:3] == ["host", "--profile", "GVE84-100"]
    flags = meta["host_flags"]
    assert flags["--expect-motion"] == SHELL_MOTION and flags["--host-timeout"] == HOST_TIMEOUT
    assert flags["--profile"] == "GVE84-100@0" and flags["--scenarios"] == "clean"
    page = (folder / "report.html").read_text()
    assert "host command" in page and "shell_host.sh" in page
    assert "--max-travel" not in page and "--full-logs" not in page


@pytest.mark.parametrize(("given", "says"), [
    ("1000,x", "whole full steps"), ("3:1,2", "no unit at address 3"),
    ("1,2,3,4", "at most 3"), ("-1,0", "none negative")])
def test_expect_motion_usage_errors(given, says, capsys):
    assert main(["--profile", "GVE84-100", f"--expect-motion={given}", "--", "true",
                 "{port}"]) == 2
    err = capsys.readouterr().err
    assert says in err and len(err.strip().splitlines()) == 1, err
