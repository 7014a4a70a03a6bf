"""Reports carry hostile wire bytes safely: escaped in HTML, well-formed in JUnit XML."""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET

from conformance.reports import write_reports
from conformance.run.runner import CaseResult, RunResult
from conformance.verdicts.verdict import ERROR, FAIL

HOSTILE = "<script>alert(1)</script> & \"quoted\" ]]></pre>"
#: what no XML document may hold and no HTML page should: NUL and control characters
RAW = "\x00\x07\x1b[31m\x7f\x9b\ud800 end"


def _run() -> RunResult:
    bad = CaseResult("5.toy.bad", "5", "toy rule", "M", "test", "GVE84-100", "emu:GVE84-100",
                     FAIL, checks=[{"ok": False, "what": HOSTILE, "observed": HOSTILE,
                                    "expected": "0", "tag": "M", "rule": "toy rule"}],
                     wire_log=["# link", f"> {HOSTILE}"])
    broken = CaseResult("6.toy.broken", "6", "toy rule", "D", "test", "GVE84-100",
                        "emu:GVE84-100", ERROR, notes=[HOSTILE])
    raw = CaseResult("7.toy.raw", "7", RAW, "M", RAW, "GVE84-100", "emu:GVE84-100", FAIL,
                     checks=[{"ok": False, "what": RAW, "observed": RAW, "expected": RAW,
                              "tag": "M", "rule": RAW}], notes=[RAW], wire_log=[RAW],
                     artifacts={RAW: RAW})
    return RunResult("toy-run", [bad, broken, raw], ["emu:GVE84-100"], problems=[RAW])


def test_hostile_text_is_escaped_everywhere(tmp_path):
    folder = write_reports(_run(), tmp_path)
    html = (folder / "report.html").read_text()
    assert "<script>alert" not in html and "&lt;script&gt;alert" in html
    cases = ET.parse(folder / "junit.xml").getroot().findall(".//testcase")
    assert len(cases) == 3
    assert [c.find("failure") is not None for c in cases] == [True, False, True]
    assert cases[1].find("error") is not None
    assert HOSTILE in "".join(cases[0].itertext())        # the wire log survives intact
    results = json.loads((folder / "results.json").read_text())
    assert results["counts"] == {FAIL: 2, ERROR: 1}


def test_control_characters_never_reach_a_report_raw(tmp_path):
    folder = write_reports(_run(), tmp_path)
    junit = (folder / "junit.xml").read_text(encoding="utf-8")
    ET.fromstring(junit)                                  # well-formed
    assert "\\x00\\x07\\x1B" in junit
    html = (folder / "report.html").read_text(encoding="utf-8")
    assert not any(c in html for c in "\x00\x07\x1b\x7f\x9b")
    assert "PROBLEM" in html.split("<h2>")[0]               # at the top
    assert json.loads((folder / "results.json").read_text())["problems"] == [RAW]
