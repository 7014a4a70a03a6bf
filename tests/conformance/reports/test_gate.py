"""A gate's reports: results.json and JUnit XML in the run's folder, one testcase per
item (failure, skipped, or passed with its lines), the gate's last line on the suite; any
text an item carries (a unit's bytes quoted in a line) leaves the file well-formed."""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET

from conformance.reports.gate import GateItem, GateRun, write_gate_reports


def test_one_testcase_per_item_and_the_last_line_on_the_suite(tmp_path):
    run = GateRun("fairness", "f1", "FAILED", "fairness score: 1/2 = 50.0 %", [
        GateItem("plus-sign", True, 1.5, ["fair    plus-sign"]),
        GateItem("hex-upper", False, 2.0, ["UNFAIR  hex-upper", "FAIL 3.x: \x1b[2J\x00"]),
        GateItem("all", None, 0.0, ["not run: the job ended before it"])],
        3.5, ["fairness", "--jobs", "2"], "2026-01-01T00:00:00+00:00")
    folder = write_gate_reports(run, tmp_path)
    assert folder == tmp_path / "f1"
    suite = ET.parse(folder / "junit.xml").getroot().find("testsuite")
    assert (suite.get("tests"), suite.get("failures"), suite.get("skipped")) == ("3", "1", "1")
    cases = {tc.get("name"): tc for tc in suite.iter("testcase")}
    assert cases["hex-upper"].find("failure").get("message") == "UNFAIR  hex-upper"
    assert "\\x1B[2J\\x00" in cases["hex-upper"].find("failure").text
    assert cases["all"].find("skipped") is not None
    assert cases["plus-sign"].find("system-out").text == "fair    plus-sign"
    assert suite.find("system-out").text == "FAILED — fairness score: 1/2 = 50.0 %\n"
    data = json.loads((folder / "results.json").read_text())
    assert data["verdict"] == "FAILED" and data["command"] == ["fairness", "--jobs", "2"]
    assert [i["passed"] for i in data["items"]] == [True, False, None]
