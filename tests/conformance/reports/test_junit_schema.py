"""The JUnit file against the constraints of Apache Ant's JUnit schema (the windyroad
JUnit.xsd that Jenkins and GitLab readers follow), written here as checks rather than
the schema file itself: the schema's text is a third party's, not carried in this
repository. Where Ant's schema is stricter than every CI reader — it has no
``properties`` or ``system-out`` inside a testcase — the file follows Jenkins' and
Surefire's schemas, which add them; everything else is Ant's:

- ``testsuites`` holds only ``testsuite`` elements, each with ``package`` and an ``id``
  counting from 0;
- a testsuite has ``name``, ``hostname`` (non-empty tokens), ``timestamp`` (a date and
  time to the second, without a zone), ``tests``, ``failures``, ``errors`` (integers),
  ``skipped`` (an integer, optional) and ``time`` (a decimal); its children in order: one
  ``properties``, the testcases, one ``system-out``, one ``system-err``;
- a property has a non-empty ``name`` and a ``value``;
- a testcase has ``name`` and ``classname`` (non-empty tokens) and ``time`` (a decimal),
  and at most one of ``skipped``, ``error``, ``failure``; an error or failure has a
  ``type``.

Besides the schema, what a dashboard reads: the counts agree with the testcases."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET

import pytest

from conformance.cli import main
from conformance.reports import render_junit
from conformance.verdicts.verdict import NON_STRICT
from tests.conformance.reports.toy import toy_run

_TIMESTAMP = re.compile(r"\d{4}-\d{2}-\d{2}T\d{2}:\d{2}:\d{2}")
_INT = re.compile(r"-?\d+")
_DECIMAL = re.compile(r"[+-]?(\d+(\.\d*)?|\.\d+)")
OUTCOMES = ("skipped", "error", "failure")


def _token(value: str | None) -> bool:
    """An xs:token of at least one character: no tab, CR, LF, no space at either end,
    no two spaces in a row."""
    return bool(value) and value == " ".join(value.split())


def _suite(suite: ET.Element, number: int) -> list[str]:
    where = f"testsuite {suite.get('name')!r}"
    bad = []
    for name, ok in (("name", _token), ("hostname", _token), ("package", _token),
                     ("timestamp", lambda v: v is not None and _TIMESTAMP.fullmatch(v)),
                     ("time", lambda v: v is not None and _DECIMAL.fullmatch(v)),
                     *((n, lambda v: v is not None and _INT.fullmatch(v))
                       for n in ("tests", "failures", "errors", "id"))):
        if not ok(suite.get(name)):
            bad.append(f"{where}: {name}={suite.get(name)!r}")
    if suite.get("skipped") is not None and not _INT.fullmatch(suite.get("skipped")):
        bad.append(f"{where}: skipped={suite.get('skipped')!r}")
    if suite.get("id") != str(number):
        bad.append(f"{where}: id {suite.get('id')!r}, expected {number}")
    tags = [child.tag for child in suite]
    if (tags[:1] != ["properties"] or tags[-2:] != ["system-out", "system-err"]
            or set(tags[1:-2]) - {"testcase"}):
        bad.append(f"{where}: children {tags[:2]}...{tags[-2:]}")
    for prop in suite.iter("property"):
        if not _token(prop.get("name")) or prop.get("value") is None:
            bad.append(f"{where}: property {prop.attrib}")
    cases = suite.findall("testcase")
    for case in cases:
        bad += _case(case)
    for count, outcome in (("tests", None), ("failures", "failure"), ("errors", "error"),
                           ("skipped", "skipped")):
        n = len(cases) if outcome is None else sum(c.find(outcome) is not None
                                                   for c in cases)
        if suite.get(count, "0") != str(n):
            bad.append(f"{where}: {count}={suite.get(count)!r}, the testcases say {n}")
    return bad


def _case(case: ET.Element) -> list[str]:
    where = f"testcase {case.get('name')!r}"
    bad = [f"{where}: {name}={case.get(name)!r}" for name in ("name", "classname")
           if not _token(case.get(name))]
    if not _DECIMAL.fullmatch(case.get("time") or ""):
        bad.append(f"{where}: time={case.get('time')!r}")
    outcomes = [child for child in case if child.tag in OUTCOMES]
    if len(outcomes) > 1:
        bad.append(f"{where}: {len(outcomes)} outcomes")
    bad += [f"{where}: {o.tag} without a type" for o in outcomes
            if o.tag != "skipped" and not o.get("type")]
    extra = {child.tag for child in case} - {*OUTCOMES, "properties", "system-out",
                                              "system-err"}
    return bad + ([f"{where}: children {sorted(extra)}"] if extra else [])


def ant_violations(text: str) -> list[str]:
    """What in the JUnit document ``text`` Ant's schema (as extended above) refuses."""
    root = ET.fromstring(text)
    if root.tag != "testsuites":
        return [f"root {root.tag}"]
    bad = [f"testsuites holds {child.tag}" for child in root if child.tag != "testsuite"]
    for number, suite in enumerate(root.findall("testsuite")):
        bad += _suite(suite, number)
    return bad


@pytest.mark.parametrize("strict", [False, True])
def test_every_verdict_fits_ant_s_schema(strict):
    run = toy_run(strict=strict)
    text = render_junit(run)
    assert ant_violations(text) == []
    lenient = ET.fromstring(text).find(".//testcase[@name='8.toy.lenient[GVE84-100]']")
    # NON-STRICT visible: a failure under --strict, else a skipped testcase saying so
    (shown,) = [child for child in lenient if child.tag in OUTCOMES]
    assert shown.tag == ("failure" if strict else "skipped")
    assert shown.get("message").startswith(f"{NON_STRICT}: ")


def test_a_fleet_s_merged_file_and_a_real_run_s_fit_it(tmp_path):
    junit = tmp_path / "fleet.xml"
    assert main(["--target", "emu:GVE54", "--target", "emu:GVE84-100?reading=plus-sign",
                 "--cases", "3.params.*", "--jobs", "2", "--no-reports", "-q",
                 "--junitxml", str(junit)]) == 0
    text = junit.read_text(encoding="utf-8")
    assert ant_violations(text) == []
    assert [s.get("id") for s in ET.fromstring(text).findall("testsuite")] == ["0", "1"]
    assert f'message="{NON_STRICT}: ' in text


@pytest.mark.parametrize(("change", "refused"), [
    (lambda t: t.replace('timestamp="2026-11-25T10:00:00"',
                         'timestamp="2026-11-25T10:00:00+01:00"'), "timestamp"),
    (lambda t: t.replace('classname="gve.GVE84-100.section6"', 'classname=""'), "classname"),
    (lambda t: t.replace('type="FAIL"', ""), "without a type"),
    (lambda t: t.replace('id="0"', 'id="1"'), "id"),
    (lambda t: t.replace('failures="1"', 'failures="0"'), "failures"),
])
def test_the_checks_refuse_what_the_schema_refuses(change, refused):
    """The checks can fail: each change breaks one of Ant's constraints."""
    text = render_junit(toy_run())
    assert ant_violations(text) == []
    assert any(refused in v for v in ant_violations(change(text)))
