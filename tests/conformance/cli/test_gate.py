"""A gate (mutation, fairness, corpus) ends as every job ends: its reports (results.json
and a JUnit testcase per item: a failure for an item that failed the gate, skipped for
one the job did not reach) where --report-dir and --junitxml say, then one last line;
--seconds bounds it, and a gate its time limit cut short ends INCOMPLETE (exit 3, 0
with --accept-incomplete), never PASSED on a score of what it did not all try."""

from __future__ import annotations

import json
import re
import xml.etree.ElementTree as ET

from conformance.cli import main
from conformance.cli.usage import INCOMPLETE_STATUS

#: a mutant the version case cannot catch, and one the error cases catch
MISSED, CAUGHT = "range-error-code", "lower-case-command"


def _testcases(path) -> dict[str, ET.Element]:
    return {tc.get("name"): tc for tc in ET.parse(path).getroot().iter("testcase")}


def test_mutation_writes_a_testcase_per_mutant_and_ends_with_its_verdict(tmp_path, capsys):
    status = main(["mutation", "--profile", "GVE84-100", "--cases", "1.profile.version",
                   "--cases", "3.frame.*", "--mutant", MISSED, "--mutant", CAUGHT,
                   "--report-dir", str(tmp_path), "--run-id", "m",
                   "--junitxml", str(tmp_path / "m.xml")])
    out = capsys.readouterr().out.strip().splitlines()
    assert status == 1 and out[-1].startswith("FAILED — mutation score: 1/2 = 50.0 %"), out
    assert f"reports: {tmp_path / 'm'}/results.json, junit.xml" in out
    for junit in (tmp_path / "m" / "junit.xml", tmp_path / "m.xml"):
        cases = _testcases(junit)
        assert set(cases) == {MISSED, CAUGHT}
        assert cases[MISSED].find("failure").get("message").startswith(f"MISSED  {MISSED}")
        assert cases[CAUGHT].find("failure") is None
    results = json.loads((tmp_path / "m" / "results.json").read_text())
    assert results["verdict"] == "FAILED" and f"FAILED — {results['reason']}" == out[-1]
    assert [(i["name"], i["passed"]) for i in results["items"]] == [(MISSED, False),
                                                                    (CAUGHT, True)]


def test_the_time_limit_ends_a_gate_incomplete(tmp_path, capsys):
    argv = ["mutation", "--profile", "GVE84-100", "--sweep", "--mutant", "sw6-inert",
            "--mutant", CAUGHT, "--seconds", "0.5", "--report-dir", str(tmp_path),
            "--run-id", "t"]
    status = main(argv)
    last = capsys.readouterr().out.strip().splitlines()[-1]
    assert status == INCOMPLETE_STATUS, last
    # how many mutants end within the limit is the machine's speed: none or one of two
    done = re.match(r"INCOMPLETE — mutation: the time limit of 0\.5 s came after ([01]) of "
                    r"2 mutants; not tested: (\d) mutant", last)
    assert done and int(done[1]) + int(done[2]) == 2, last
    cases = _testcases(tmp_path / "t" / "junit.xml")
    skipped = [tc for tc in cases.values() if tc.find("skipped") is not None]
    assert len(cases) == 2 and len(skipped) == int(done[2])
    assert json.loads((tmp_path / "t" / "results.json").read_text())["verdict"] == "INCOMPLETE"
    assert main([*argv[:-1], "t2", "--accept-incomplete"]) == 0


def test_the_time_limit_stops_the_workers_too(capsys):
    status = main(["mutation", "--no-reports", "--jobs", "2", "--profile", "GVE84-100",
                   "--sweep", "--mutant", "sw6-inert", "--mutant", CAUGHT, "--mutant",
                   MISSED, "--seconds", "0.5"])
    last = capsys.readouterr().out.strip().splitlines()[-1]
    assert status == INCOMPLETE_STATUS and "the time limit of 0.5 s came after" in last, last
