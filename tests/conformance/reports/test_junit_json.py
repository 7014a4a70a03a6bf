"""JUnit XML and JSON: the run's metadata and verdict, per-testcase properties that
show NON-STRICT and INFO, well-formed whatever the unit sent; what a CI's JUnit reader
(junitparser here) makes of NON-STRICT, INFO and COULD-NOT-TEST, with and without
--strict; classnames that split into package and class as Jenkins splits them."""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET

from junitparser import Failure, JUnitXml, Properties, Skipped

from conformance.reports import to_json, write_junit, write_reports
from conformance.verdicts.explain import plain
from conformance.verdicts.verdict import FAILED
from gve_fixtures.rules import load_rules
from tests.conformance.reports.toy import HOSTILE, toy_run


def _props(el: ET.Element) -> dict[str, str]:
    return {p.get("name"): p.get("value") for p in el.findall("./properties/property")}


def test_junit_carries_timestamp_hostname_and_verdicts(tmp_path):
    path = write_junit(toy_run(), tmp_path / "ci" / "gve.xml")     # --junitxml PATH
    suite = ET.parse(path).getroot().find("testsuite")
    # Ant's schema takes no zone: the local time the run began, the zone in a property
    assert suite.get("timestamp") == "2026-11-25T10:00:00" and suite.get("hostname")
    props = _props(suite)
    assert props["started"] == "2026-11-25T10:00:00+01:00"
    assert props["--seed"] == "1234" and props["operator"] == "J. Novák"
    assert props["unit version (?)"] == "IP84 v3 27.1.2010"
    assert props["run verdict"].startswith(FAILED)
    cases = {c.get("name"): _props(c) for c in suite.findall("testcase")}
    assert cases["8.toy.lenient[GVE84-100]"]["verdict"] == "NON-STRICT"
    assert cases["9.toy.informs[GVE84-100]"]["verdict"] == "INFO"
    assert cases["10.5.toy.passes[GVE84-100]"] == {
        "verdict": "PASS", "tag": "M", "section": "10.5 KEEP / RESTORE"}


def test_junit_is_well_formed_with_hostile_bytes(tmp_path):
    text = write_junit(toy_run(), tmp_path / "j.xml").read_text(encoding="utf-8")
    root = ET.fromstring(text)                              # raises if not well-formed
    failure = root.find(".//testcase[@name='6.toy.fails[GVE84-100]']/failure")
    assert "</pre><script>alert(1)</script>" in failure.text
    assert "\\x00\\x07\\x1B" in failure.text and "\x00" not in text


def test_json_has_the_same_metadata_and_the_overall_verdict(tmp_path, no_plots):
    folder = write_reports(toy_run(), tmp_path)
    data = json.loads((folder / "results.json").read_text())
    assert data["verdict"] == FAILED and "1 FAIL" in data["reason"]
    assert data["meta"]["seed"] == 1234 and data["meta"]["operator"] == "J. Novák"
    assert data["meta"]["started"] == "2026-11-25T10:00:00+01:00"
    assert data["meta"]["targets"][0]["processor_id"] == "25020304"
    passing = next(r for r in data["results"] if r["id"] == "10.5.toy.passes")
    assert passing["wire_log_lines"] == 100 and len(passing["wire_log"]) == 3
    # the first check; the count says the rest passed
    assert passing["checks_total"] == 50 and len(passing["checks"]) == 1
    assert data["sections"]["10.5"] == "KEEP / RESTORE"
    assert data["cases"]["10.5.toy.passes"]["rule"] == "a rule"
    moving = next(r for r in data["results"] if r["id"] == "10.2.toy.moves")
    assert moving["traces_total"] == 1 and moving["traces"] == []     # drawn on the page
    failing = next(r for r in data["results"] if r["id"] == "6.toy.fails")
    assert failing["wire_log"][-1] == f"< {HOSTILE}"       # JSON escapes by itself
    assert to_json(toy_run(full_logs=True))["results"][0]["wire_log_lines"] == 100


def _read(run, path):
    """The JUnit file of ``run`` as a CI reads it: its one suite, its cases by name."""
    (suite,) = JUnitXml.fromfile(str(write_junit(run, path)))
    return suite, {case.name: case for case in suite}


def _case_props(case) -> dict[str, str]:
    return {p.name: p.value for p in case.child(Properties) or ()}


def test_a_ci_reader_sees_non_strict_and_info_as_skipped_with_the_verdict_first(tmp_path):
    """Neither a pass nor a failure: the one other state a CI's test view shows with a
    text, so a dashboard shows the difference and the rule it is about."""
    suite, cases = _read(toy_run(), tmp_path / "junit.xml")
    lenient, informs = cases["8.toy.lenient[GVE84-100]"], cases["9.toy.informs[GVE84-100]"]
    for case, verdict, rule, tag in ((lenient, "NON-STRICT", "8.repeat.answer", "D"),
                                     (informs, "INFO", "10.3.st6.free", "D-info")):
        (skipped,) = case.result
        assert isinstance(skipped, Skipped) and skipped.message.startswith(f"{verdict}: ")
        assert f"{rule} [{tag}]" in skipped.message
        assert _case_props(case)["verdict"] == verdict
        assert case.system_out.splitlines()[0] == skipped.message
    assert '"5"' in lenient.result[0].message and '"0"' in lenient.result[0].message
    counts = {p.name: p.value for p in suite.properties() if p.name.startswith("count ")}
    assert counts == {"count PASS": "2", "count MISSING": "0", "count COULD-NOT-TEST": "1",
                      "count INFO": "1", "count NON-STRICT": "1", "count FAIL": "1",
                      "count ERROR": "0"}
    assert (suite.tests, suite.failures, suite.errors, suite.skipped) == (6, 1, 0, 3)


def test_a_failure_names_the_rule_and_cites_its_sentence(tmp_path):
    run = toy_run()
    run.results[2].checks[0]["rule"] = "1.profile.dollar-range"
    _, cases = _read(run, tmp_path / "junit.xml")
    (failure,) = cases["6.toy.fails[GVE84-100]"].result
    assert isinstance(failure, Failure) and failure.type == "FAIL"
    assert failure.message.startswith("FAIL: 1.profile.dollar-range [M] ")
    rule = load_rules()["1.profile.dollar-range"]
    out = cases["6.toy.fails[GVE84-100]"].system_out
    # its sentence as plain text: the Markdown of rules.toml without its backticks
    assert f"the rule: {plain(rule.text)} ({plain(rule.source)})" in out and "`" not in out


def test_could_not_test_is_skipped_with_its_reason(tmp_path):
    _, cases = _read(toy_run(), tmp_path / "junit.xml")
    hand = cases["10.3.toy.needs-a-hand[GVE84-100]"]
    (skipped,) = hand.result
    assert isinstance(skipped, Skipped) and skipped.message.startswith("COULD-NOT-TEST: ")
    assert "nobody grounded IN0 (X limit)" in skipped.message


def test_under_strict_non_strict_is_a_failure_and_info_still_skipped(tmp_path):
    suite, cases = _read(toy_run(strict=True), tmp_path / "junit.xml")
    lenient = cases["8.toy.lenient[GVE84-100]"]
    (failure,) = lenient.result
    assert isinstance(failure, Failure) and failure.type == "NON-STRICT"
    assert failure.message.startswith("NON-STRICT: 8.repeat.answer [D]")
    (skipped,) = cases["9.toy.informs[GVE84-100]"].result
    assert isinstance(skipped, Skipped) and skipped.message.startswith("INFO: ")
    assert suite.failures == 2            # the FAIL and the NON-STRICT
    assert suite.skipped == 2             # the INFO and the COULD-NOT-TEST
    assert {p.name: p.value for p in suite.properties()}["--strict"] == "True"


def test_a_classname_splits_at_its_last_dot_into_profile_and_section(tmp_path):
    """Jenkins takes what precedes a classname's last dot as the package and the rest as
    the class: the profile's package, the spec section's class (10.5 has a dot)."""
    _, cases = _read(toy_run(), tmp_path / "junit.xml")
    for name, section in (("10.5.toy.passes", "10.5"), ("6.toy.fails", "6")):
        package, _, cls = cases[f"{name}[GVE84-100]"].classname.rpartition(".")
        assert package == "gve.GVE84-100"
        assert cls.removeprefix("section").replace("_", ".") == section
