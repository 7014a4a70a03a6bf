"""JUnit XML as a CI's test view reads it (Ant's JUnit schema, with the testcase
``properties`` and ``system-out`` that Jenkins' and Surefire's schemas add): testsuites >
testsuite (one per target: ``package`` and ``id``, a timestamp without a zone, the
hostname, the run's flags, the unit's identity and the count of each verdict as
properties; its ``system-out`` the run's verdict line) > testcase.

A testcase is named ``<case>[<profile>]`` whatever its verdict (a CI's history of a case
survives a change of verdict); its classname ``gve.<profile>.section<N_M>`` splits at its
last dot, as Jenkins splits it, into the package ``gve.<profile>`` and the class of its
spec section. CI tools know only pass, fail, error and skip (docs/ci.md):

- FAIL is a ``failure``, ERROR an ``error``; NON-STRICT a ``failure`` under ``--strict``;
- NON-STRICT (by the tags) and INFO are ``skipped`` whose message begins with the verdict:
  the one state a dashboard shows that is neither a pass nor a failure, with its text;
- COULD-NOT-TEST and MISSING are ``skipped`` with their reason.

Every message is the verdict and why (conformance/verdicts/explain.py: the deciding check's rule,
tag, what was seen and wanted); the ``system-out`` of a case that did not PASS adds the
rule's sentence and its source, then the wire log. Every text goes through
:func:`clean`, so any bytes from a unit leave the file well-formed."""

from __future__ import annotations

import datetime
import xml.etree.ElementTree as ET
from pathlib import Path

from conformance.reports.banner import run_verdict
from conformance.reports.files import write_text
from conformance.reports.logs import compact
from conformance.reports.sections import section_title
from conformance.reports.text import element
from conformance.run.runner import CaseResult, RunResult
from conformance.verdicts.explain import plain, reason
from conformance.verdicts.verdict import (
    COULD_NOT_TEST,
    ERROR,
    FAIL,
    INFO,
    MISSING,
    NON_STRICT,
    ORDER,
    PASS,
)

#: verdicts a CI sees as skipped (unless --strict makes NON-STRICT a failure)
SKIPPED = (NON_STRICT, INFO, COULD_NOT_TEST, MISSING)


def classname(profile: str, section: str) -> str:
    """``gve.GVE84-100.section10_3``: no dot but the one between package and class."""
    return f"gve.{profile.replace('.', '_')}.section{section.replace('.', '_')}"


def package(profile: str) -> str:
    """The package a classname of ``profile`` splits into (a testsuite's ``package``)."""
    return classname(profile, "").rpartition(".")[0]


def timestamp(started: str) -> str:
    """An ISO 8601 time as Ant's schema takes it: to the second, without a zone (the
    local time the run began; the zone is in the suite's ``started`` property)."""
    try:
        when = datetime.datetime.fromisoformat(started)
    except ValueError:
        when = datetime.datetime.now()
    return when.strftime("%Y-%m-%dT%H:%M:%S")


def message(r: CaseResult) -> str:
    """``NON-STRICT: 8.repeat.answer [D] > repeats the last frame: observed "5",
    expected "0"``: the verdict and why."""
    return f"{r.verdict}: {reason(r).line()}"


def _failed(r: CaseResult, strict: bool) -> bool:
    """Whether CI sees the case as a failure: a FAIL, and under ``--strict`` a NON-STRICT."""
    return r.verdict == FAIL or (strict and r.verdict == NON_STRICT)


def _properties(parent: ET.Element, items: dict[str, object]) -> None:
    props = element(parent, "properties")
    for key, value in items.items():
        element(props, "property", name=key, value=value)


def _head(r: CaseResult) -> str:
    """The first lines of a case's output: its verdict and why, the rule's sentence, the
    case itself."""
    why = reason(r)
    return "\n".join([message(r), *([f"the rule: {why.cites()}"] if why.rule else []),
                      f"the case: {r.id}, tag {r.tag}, section {section_title(r.section)}; "
                      f"{plain(r.rule)} ({plain(r.source)})", ""])


def _testcase(suite: ET.Element, r: CaseResult, strict: bool, full: bool) -> None:
    tc = element(suite, "testcase", name=f"{r.id}[{r.profile}]",
                  classname=classname(r.profile, r.section), time=f"{r.seconds:.3f}")
    _properties(tc, {"verdict": r.verdict, "tag": r.tag,
                     "section": section_title(r.section)})
    log = "\n".join(compact(r.wire_log, r.verdict, full))
    failed = _failed(r, strict)
    if failed:
        element(tc, "failure", log, message=message(r), type=r.verdict)
    elif r.verdict == ERROR:
        element(tc, "error", "\n".join(r.notes) + "\n" + log, message=message(r),
                 type=r.verdict)
    elif r.verdict in SKIPPED:
        element(tc, "skipped", message=message(r))
    if r.verdict == PASS and not full:
        return                  # its properties say it all; the JSON keeps the rest
    # the log once: in the failure or error when there is one
    element(tc, "system-out", _head(r) + ("" if failed or r.verdict == ERROR else log))


def _testsuite(root: ET.Element, run: RunResult, target: str, number: int, full: bool
               ) -> None:
    strict = run.meta.strict
    results = [r for r in run.results if r.target == target]
    t = run.meta.target(target)
    profile = t.profile or (results[0].profile if results else "")
    verdict, reason_text = run_verdict(run)
    suite = element(
        root, "testsuite", name=target, package=package(profile), id=number,
        tests=len(results), failures=sum(_failed(r, strict) for r in results),
        errors=sum(r.verdict == ERROR for r in results),
        skipped=sum(r.verdict in SKIPPED and not _failed(r, strict) for r in results),
        time=f"{sum(r.seconds for r in results):.3f}",
        timestamp=timestamp(run.meta.started), hostname=run.meta.host or "localhost")
    _properties(suite, {
        "run verdict": f"{verdict} ({reason_text})", "target": target,
        "started": run.meta.started, "finished": run.meta.finished,
        **{f"problem {i + 1}": p for i, p in enumerate(run.problems)},
        "profiles": " ".join(sorted({r.profile for r in results})),
        "unit version (?)": t.version, "unit processor id (Q)": t.processor_id,
        "operator": run.meta.operator, "suite version": run.meta.suite_version,
        **{flag: value for flag, value in run.meta.flags().items()},
        **{f"count {v}": sum(r.verdict == v for r in results) for v in reversed(ORDER)}})
    for r in results:
        _testcase(suite, r, strict, full)
    element(suite, "system-out", f"{verdict} — {reason_text}\n")
    element(suite, "system-err", "")


def render_junit(run: RunResult, full_logs: bool | None = None) -> str:
    full = run.meta.full_logs if full_logs is None else full_logs
    root = ET.Element("testsuites", name="gve-conformance", tests=str(len(run.results)),
                      time=f"{run.seconds:.3f}")
    for number, target in enumerate(run.targets):
        _testsuite(root, run, target, number, full)
    return ET.tostring(root, encoding="unicode", xml_declaration=True)


def write_junit(run: RunResult, path: str | Path) -> Path:
    """The JUnit file at ``path`` (``--junitxml``: where a CI expects it)."""
    return write_text(path, render_junit(run))
