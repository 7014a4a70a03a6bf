"""The command line and the three reports."""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET

import pytest

from conformance.cli import main
from gve_fixtures.profile import load_profile


def test_a_run_writes_three_reports(tmp_path, capsys):
    status = main(["--target", "emu:GVE84-100", "--cases", "5.*", "--cases", "11.golden.g1*",
                   "--report-dir", str(tmp_path)])
    out = capsys.readouterr().out
    assert status == 0
    assert "frames exchanged" in out
    (folder,) = tmp_path.iterdir()
    suites = ET.parse(folder / "junit.xml").getroot()
    cases = suites.findall("./testsuite/testcase")
    assert cases and all(c.get("name") and c.get("classname") and c.get("time") for c in cases)
    # a testcase holds only these (its properties first, as pytest writes them), the
    # result before system-out
    allowed = ["properties", "skipped", "error", "failure", "system-out", "system-err"]
    for c in cases:
        tags = [child.tag for child in c]
        assert all(t in allowed for t in tags) and tags == sorted(tags, key=allowed.index)
    for suite in suites.findall("./testsuite"):
        assert suite.get("name") and suite.get("tests") == str(len(suite.findall("testcase")))
    results = json.loads((folder / "results.json").read_text())
    judged = [c for c in cases if c.find("skipped") is None]      # MISSING is skipped
    assert results["counts"].get("PASS") == len(judged)
    html = (folder / "report.html").read_text()
    assert "<link" not in html and "<script src" not in html      # self-contained
    assert "5.errors.go-without-inta" in html and "!0G" in html      # the wire log


def test_a_mutant_fails_the_run(tmp_path, capsys):
    status = main(["--target", "emu:GVE84-100", "--cases", "5.errors.go-without-inta",
                   "--mutant", "go-without-inta", "--no-reports"])
    assert status == 1
    assert "FAIL" in capsys.readouterr().out


def test_bad_targets_are_explained(capsys):
    assert main(["--target", "carrier-pigeon:x"]) == 2
    assert main(["--target", "serial:/dev/null"]) == 2      # needs --profile
    assert "--profile" in capsys.readouterr().err


def test_list(capsys):
    assert main(["--list"]) == 0
    assert "11.golden.g6-keep-restore" in capsys.readouterr().out


def test_emu_all_means_every_profile(capsys):
    assert main(["--target", "emu:all", "--cases", "5.errors.go-without-inta",
                 "--no-reports", "-v"]) == 0
    out = capsys.readouterr().out
    assert "8 case runs on 8 target(s)" in out and "[GVE54]" in out and "[GVE114-500]" in out


def test_an_unknown_profile_is_explained(capsys):
    assert main(["--target", "emu:GVE99", "--no-reports"]) == 2
    assert "GVE99" in capsys.readouterr().err


@pytest.mark.parametrize("argv", [
    ["--target", "emu:GVE84-100", "--no-reports"],
    ["--target", "serial:/dev/null", "--profile", "{file}", "--no-reports"],
    ["--coverage"],
    ["diff", "--target", "emu:GVE84-100", "--no-reports"],
    ["host", "--profile", "GVE84-100", "--no-reports", "--", "true", "{port}"],
])
def test_a_misspelt_profile_key_stops_every_command_in_one_line(argv, tmp_path, monkeypatch,
                                                               capsys):
    text = load_profile("GVE84-100").path.read_text()
    path = tmp_path / "GVE84-100.toml"       # overrides the shipped one (GVE_PROFILE_PATH)
    path.write_text(text.replace("watchdog_ms =", "watchdog_mss =", 1))
    monkeypatch.setenv("GVE_PROFILE_PATH", str(tmp_path))
    assert main([a.replace("{file}", str(path)) for a in argv]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.endswith(
        f"{path}: unknown key 'link.watchdog_mss' (did you mean 'link.watchdog_ms'?)\n")
