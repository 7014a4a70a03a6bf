"""JUnit XML in the common (Ant/Jenkins junit-10) schema: testsuites > testsuite (one per
target, with its properties) > testcase (skipped | error | failure, then system-out).
A testcase carries no properties there, so its verdict, tag, rule and source head its
system-out, above the wire log."""

from __future__ import annotations

import xml.etree.ElementTree as ET

from conformance.reports.clean import clean
from conformance.runner import CaseResult, RunResult
from conformance.verdict import COULD_NOT_TEST, ERROR, FAIL, MISSING


def _message(r: CaseResult) -> str:
    failed = r.failed_checks
    if failed:
        c = failed[0]
        return f"[{c['tag']}] {c['what']} (observed {c['observed']!r}, expected {c['expected']!r})"
    return "; ".join(r.notes)[:500] or r.verdict


def render_junit(run: RunResult) -> str:
    root = ET.Element("testsuites", name="gve-conformance", tests=str(len(run.results)),
                      time=f"{run.seconds:.3f}")
    for target in run.targets:
        results = [r for r in run.results if r.target == target]
        suite = ET.SubElement(
            root, "testsuite", name=target, tests=str(len(results)),
            failures=str(sum(r.verdict == FAIL for r in results)),
            errors=str(sum(r.verdict == ERROR for r in results)),
            skipped=str(sum(r.verdict in (MISSING, COULD_NOT_TEST) for r in results)),
            time=f"{sum(r.seconds for r in results):.3f}")
        props = ET.SubElement(suite, "properties")
        for key, value in (("target", target), ("settings", run.settings),
                           ("profiles", " ".join(sorted({r.profile for r in results})))):
            ET.SubElement(props, "property", name=key, value=value)
        for r in results:
            tc = ET.SubElement(suite, "testcase", name=f"{r.id}[{r.profile}]",
                               classname=f"gve.{r.profile}.section{r.section}",
                               time=f"{r.seconds:.3f}")
            head = (f"verdict {r.verdict}; tag {r.tag}; section {r.section}; "
                    f"source {r.source}\nrule: {r.rule}\n")
            log = "\n".join(r.wire_log)
            if r.verdict == FAIL:
                ET.SubElement(tc, "failure", message=_message(r), type=r.verdict).text = log
            elif r.verdict == ERROR:
                ET.SubElement(tc, "error", message=_message(r), type=r.verdict).text = (
                    "\n".join(r.notes) + "\n" + log)
            elif r.verdict in (MISSING, COULD_NOT_TEST):
                ET.SubElement(tc, "skipped", message=f"{r.verdict}: {_message(r)}")
            ET.SubElement(tc, "system-out").text = head + log
    for element in root.iter():         # any unit bytes: always well-formed XML
        element.text = None if element.text is None else clean(element.text)
        element.attrib = {k: clean(v) for k, v in element.attrib.items()}
    return ET.tostring(root, encoding="unicode", xml_declaration=True)
