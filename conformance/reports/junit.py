"""JUnit XML: testsuites > testsuite (one per target: timestamp, hostname, the run's
flags, the unit's identity and the count of each verdict as properties) > testcase (its
verdict, tag and section as properties; then skipped | error | failure; then system-out,
whose first line is the verdict and the rule it grades, then the case's head and wire
log). CI tools know only pass, fail, error and skip: NON-STRICT and INFO pass and say so
in that first line, and a run whose metadata says ``strict`` makes NON-STRICT a failure
(docs/ci.md). Every text goes through :func:`clean`, so any bytes from a unit leave the
file well-formed."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

from conformance.quoting import quoted
from conformance.reports.banner import run_verdict
from conformance.reports.files import write_text
from conformance.reports.logs import compact
from conformance.reports.sections import section_title
from conformance.reports.text import clean
from conformance.runner import CaseResult, RunResult
from conformance.verdict import (COULD_NOT_TEST, ERROR, FAIL, MISSING, NON_STRICT, ORDER, PASS,
                                 CHECK_TAGS, grade)
from gve_fixtures.rules import load_rules


def _deciding(r: CaseResult) -> dict | None:
    """The failed check that gave the case its verdict: the worst graded, the first of
    those."""
    def rank(c: dict) -> int:
        return ORDER.index(grade(c["tag"], False)) if c["tag"] in CHECK_TAGS else 0
    return min(r.failed_checks, key=rank, default=None)


def _message(r: CaseResult) -> str:
    c = _deciding(r)
    if c is not None:
        return (f"[{c['tag']}] {c['what']} (observed {quoted(c['observed'])}, "
                f"expected {quoted(c['expected'])})")
    return "; ".join(r.notes)[:500] or r.verdict


def _verdict_line(r: CaseResult) -> str:
    """``NON-STRICT 8.repeat.answer: [D] ...``: the verdict, the rule the deciding check
    judges (the case's ID when it names none), and what was seen."""
    c = _deciding(r)
    rule = c["rule"] if c is not None and c["rule"] in load_rules() else r.id
    seen = _message(r)
    return f"{r.verdict} {rule}" + ("" if seen == r.verdict else f": {seen}")


def _failed(r: CaseResult, strict: bool) -> bool:
    """Whether CI sees the case as a failure: a FAIL, and under ``--strict`` a NON-STRICT."""
    return r.verdict == FAIL or (strict and r.verdict == NON_STRICT)


def _element(parent: ET.Element, tag: str, text: str | None = None, **attrs: object
             ) -> ET.Element:
    el = ET.SubElement(parent, tag, {k: clean(v) for k, v in attrs.items()})
    if text is not None:
        el.text = clean(text)
    return el


def _properties(parent: ET.Element, items: dict[str, object]) -> None:
    props = _element(parent, "properties")
    for key, value in items.items():
        _element(props, "property", name=key, value=value)


def render_junit(run: RunResult, full_logs: bool | None = None) -> str:
    full = run.meta.full_logs if full_logs is None else full_logs
    strict = run.meta.strict
    verdict, reason = run_verdict(run)
    root = _element(ET.Element("dummy"), "testsuites", name="gve-conformance",
                    tests=len(run.results), time=f"{run.seconds:.3f}")
    for target in run.targets:
        results = [r for r in run.results if r.target == target]
        t = run.meta.target(target)
        suite = _element(
            root, "testsuite", name=target, tests=len(results),
            failures=sum(_failed(r, strict) for r in results),
            errors=sum(r.verdict == ERROR for r in results),
            skipped=sum(r.verdict in (MISSING, COULD_NOT_TEST) for r in results),
            time=f"{sum(r.seconds for r in results):.3f}",
            timestamp=run.meta.started, hostname=run.meta.host)
        _properties(suite, {
            "run verdict": f"{verdict} ({reason})", "target": target,
            **{f"problem {i + 1}": p for i, p in enumerate(run.problems)},
            "profiles": " ".join(sorted({r.profile for r in results})),
            "unit version (?)": t.version, "unit processor id (Q)": t.processor_id,
            "operator": run.meta.operator, "suite version": run.meta.suite_version,
            **{flag: value for flag, value in run.meta.flags().items()},
            **{f"count {v}": sum(r.verdict == v for r in results) for v in reversed(ORDER)}})
        for r in results:
            tc = _element(suite, "testcase", name=f"{r.id}[{r.profile}]",
                          classname=f"gve.{r.profile}.section{r.section}",
                          time=f"{r.seconds:.3f}")
            _properties(tc, {"verdict": r.verdict, "tag": r.tag,
                             "section": section_title(r.section)})
            log = "\n".join(compact(r.wire_log, r.verdict, full))
            line = _verdict_line(r)
            failed = _failed(r, strict)
            if failed:
                _element(tc, "failure", log, message=line, type=r.verdict)
            elif r.verdict == ERROR:
                _element(tc, "error", "\n".join(r.notes) + "\n" + log, message=line,
                         type=r.verdict)
            elif r.verdict in (MISSING, COULD_NOT_TEST):
                _element(tc, "skipped", message=line)
            if r.verdict == PASS and not full:
                continue            # its properties say it all; the JSON keeps the rest
            head = (f"{line}\ntag {r.tag}; section {r.section}; source {r.source}\n"
                    f"rule: {r.rule}\n")
            # the log once: in the failure or error when there is one
            _element(tc, "system-out", head + ("" if failed or r.verdict == ERROR else log))
    return ET.tostring(root, encoding="unicode", xml_declaration=True)


def write_junit(run: RunResult, path: str | Path) -> Path:
    """The JUnit file at ``path`` (``--junitxml``: where a CI expects it)."""
    return write_text(path, render_junit(run))
