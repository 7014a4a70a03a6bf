"""Reports carry hostile wire bytes safely: escaped in HTML, well-formed in JUnit XML."""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET

from conformance.reports import write_reports
from conformance.runner import CaseResult, RunResult
from conformance.verdict import ERROR, FAIL

HOSTILE = "<script>alert(1)</script> & \"quoted\" ]]>"


def _run() -> RunResult:
    bad = CaseResult("5.toy.bad", "5", "toy rule", "M", "test", "GVE84-100", "emu:GVE84-100",
                     FAIL, checks=[{"ok": False, "what": HOSTILE, "observed": HOSTILE,
                                    "expected": "0", "tag": "M", "rule": "toy rule"}],
                     wire_log=["# link", f"> {HOSTILE}"])
    broken = CaseResult("6.toy.broken", "6", "toy rule", "D", "test", "GVE84-100",
                        "emu:GVE84-100", ERROR, notes=[HOSTILE])
    return RunResult("toy-run", [bad, broken], ["emu:GVE84-100"])


def test_hostile_text_is_escaped_everywhere(tmp_path):
    folder = write_reports(_run(), tmp_path)
    html = (folder / "report.html").read_text()
    assert "<script>alert" not in html and "&lt;script&gt;alert" in html
    cases = ET.parse(folder / "junit.xml").getroot().findall(".//testcase")
    assert len(cases) == 2
    assert [c.find("failure") is not None for c in cases] == [True, False]
    assert cases[1].find("error") is not None
    assert HOSTILE in "".join(cases[0].itertext())        # the wire log survives intact
    results = json.loads((folder / "results.json").read_text())
    assert results["counts"] == {FAIL: 1, ERROR: 1}
