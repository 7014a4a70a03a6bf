"""What every job of `gve-conformance` prints and how it ends: a run's ID, one line per
result as it comes, then the recap — the cases to look at listed again (ERROR, FAIL,
NON-STRICT: each with why and the rule's sentence), where the reports are, and the
verdict line (what was judged, what was not tested and why) — also under ``-q``; the exit
status (0 when the verdict line says PASSED, else 1)."""

from __future__ import annotations

import time
import uuid
from collections.abc import Callable, Sequence
from pathlib import Path

from conformance.cli.colour import paint
from conformance.cli.usage import exit_status
from conformance.reports import write_junit, write_reports
from conformance.reports.failures import failures
from conformance.runner import CaseResult, RunResult
from conformance.verdict import ORDER, PASSED, last_line, overall


def new_run_id() -> str:
    return time.strftime("%Y%m%d-%H%M%S") + "-" + uuid.uuid4().hex[:6]


def progress(quiet: bool, detail: Callable[[CaseResult], str | None]
             ) -> Callable[[CaseResult], None]:
    """A printer of one line per result (``quiet``: none), with ``detail(result)`` after
    it when there is one."""
    def show(r: CaseResult) -> None:
        if quiet:
            return
        more = detail(r)
        print(f"{r.verdict:15} {r.id} [{r.profile}]{f'  -- {more}' if more else ''}",
              flush=True)
    return show


def counted(result: RunResult) -> str:
    """``PASS 17, INFO 1``: the verdicts, worst first."""
    counts = result.counts()
    return ", ".join(f"{v} {counts[v]}" for v in ORDER if v in counts)


def recap(result: RunResult, colour: bool = False) -> list[str]:
    """The cases to look at, listed again at the end of a job: ERROR, FAIL, then
    NON-STRICT, each once for every profile it failed on alike, with why (the deciding
    check) and the sentence of the rule it judges; nothing when there are none."""
    found = failures(result)
    if not found:
        return []
    lines = [f"what failed ({len(found)}):"]
    for f in found:
        why = f.why
        lines.append(f"{paint(f.verdict, f'{f.verdict:10}', colour)} {f.id} "
                     f"[{', '.join(r.profile for r in f.runs)}]")
        lines.append(f"    {why.line()}")
        if why.rule:
            lines.append(f"    the rule: {why.cites()}")
    return lines


def say_all(lines: Sequence[str]) -> None:
    for line in lines:
        print(line, flush=True)


def end(result: RunResult, report_dir: str | Path | None, *,
        junitxml: str | Path | None = None, colour: bool = False) -> int:
    """The end of a job: the recap, the reports written (unless ``report_dir`` is None)
    and where, then the verdict line — the same under ``-q``, since it is what a log is
    read for; the exit status: 0 for PASSED, 1 otherwise, 130 when a signal stopped the
    job."""
    say_all(recap(result, colour))
    if report_dir is not None:
        folder = write_reports(result, report_dir)
        print(f"reports: {folder}/report.html, results.json, junit.xml")
    if junitxml:
        print(f"JUnit XML: {write_junit(result, junitxml)}")
    verdict, _ = overall(result.results, result.interrupted, result.problems)
    line = last_line(result.results, result.interrupted, result.problems)
    print(paint(verdict, verdict, colour) + line[len(verdict):], flush=True)
    return exit_status(verdict == PASSED, result.interrupted)
