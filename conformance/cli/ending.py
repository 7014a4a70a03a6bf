"""What every job of `gve-conformance` prints and how it ends: a run's ID and folder
(taken before the run: never another run's), one line per result as it comes, then the
recap — the cases to look at listed again (ERROR, FAIL, NON-STRICT: each with why and the
rule's sentence), where the reports are (or one line saying which file could not be
written and why: then the exit status is not 0), and the verdict line (what was judged,
what was not tested and why) — also under ``-q``; the exit status (0 when the verdict
line says PASSED, 3 when it says INCOMPLETE, else 1)."""

from __future__ import annotations

import sys
from collections.abc import Callable, Sequence
from pathlib import Path

from conformance.cli.colour import paint
from conformance.cli.usage import UsageError, verdict_status
from conformance.reports import ReportNotWritten, write_junit, write_reports
from conformance.reports.failures import failures
from conformance.reports.files import RunFolderTaken, claim, new_run_id
from conformance.run.runner import CaseResult, RunResult
from conformance.verdicts.verdict import ERROR, FAIL, MISSING, NON_STRICT, ORDER, last_line, overall

__all__ = ["claimed", "counted", "end", "new_run_id", "progress", "recap", "result_line",
           "say_all", "written"]


def claimed(report_dir: str | Path, run_id: str | None = None) -> Path:
    """The run's report folder, taken now, before anything is sent (a fresh id when
    ``run_id`` is None); UsageError when the id names another run's folder."""
    try:
        return claim(report_dir, run_id)
    except (RunFolderTaken, ReportNotWritten) as err:
        raise UsageError(str(err)) from None


def written(write: Callable[[], Path], prog: str = "gve-conformance") -> Path | None:
    """What ``write()`` wrote, or None after one line on standard error naming the file
    that could not be written and why (a full disk): the run's unit is restored by then,
    its verdict still printed, its exit status not 0."""
    try:
        return write()
    except ReportNotWritten as err:
        print(f"{prog}: {err}", file=sys.stderr, flush=True)
        return None


def result_line(r: CaseResult, more: str | None) -> str:
    """One result's line: its verdict, ID and profile, and ``more`` (why) after it."""
    return f"{r.verdict:15} {r.id} [{r.profile}]{f'  -- {more}' if more else ''}"


def progress(quiet: bool, detail: Callable[[CaseResult], str | None]
             ) -> Callable[[CaseResult], None]:
    """A printer of one line per result (``quiet``: none), with ``detail(result)`` after
    it when there is one."""
    def show(r: CaseResult) -> None:
        if quiet:
            return
        print(result_line(r, detail(r)), flush=True)
    return show


#: what a count of a verdict means where the word alone reads like a defect
MEANING = {MISSING: "not in the profile: nothing to test"}


def counted(result: RunResult) -> str:
    """``PASS 1219, MISSING 181 (not in the profile: nothing to test)``: the verdicts,
    worst first."""
    counts = result.counts()
    return ", ".join(f"{v} {counts[v]}" + (f" ({MEANING[v]})" if v in MEANING else "")
                     for v in ORDER if v in counts)


#: the recap's lists: what failed (ERROR, FAIL), then what only departs from the
#: project's decisions (NON-STRICT: not a failure, and not counted as one)
RECAP = (("what failed", (ERROR, FAIL)),
         ("what departs from the project's decisions, NON-STRICT", (NON_STRICT,)))


def recap(result: RunResult, colour: bool = False) -> list[str]:
    """The cases to look at, listed again at the end of a job: what failed (ERROR,
    FAIL), then NON-STRICT under its own heading, each once for every profile it failed
    on alike, with why (the deciding check) and the sentence of the rule it judges;
    nothing when there are none."""
    found = failures(result)
    lines: list[str] = []
    for heading, verdicts in RECAP:
        listed = [f for f in found if f.verdict in verdicts]
        if listed:
            lines.append(f"{heading} ({len(listed)}):")
        for f in listed:
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
        junitxml: str | Path | None = None, colour: bool = False,
        accept_incomplete: bool = False) -> int:
    """The end of a job: the recap, the reports written (unless ``report_dir`` is None)
    and where, then the verdict line — the same under ``-q``, since it is what a log is
    read for; the exit status: 0 for PASSED, 3 for INCOMPLETE (0 when
    ``accept_incomplete``), 1 otherwise, 130 when a signal stopped the job."""
    say_all(recap(result, colour))
    lost = False                        # a report that could not be written (a full disk)
    if report_dir is not None:
        folder = written(lambda: write_reports(result, report_dir))
        lost = folder is None
        if folder is not None:
            print(f"reports: {folder}/report.html, results.json, junit.xml")
    if junitxml:
        junit = written(lambda: write_junit(result, junitxml))
        lost = lost or junit is None
        if junit is not None:
            print(f"JUnit XML: {junit}")
    verdict, _ = overall(result.results, result.interrupted, result.problems)
    line = last_line(result.results, result.interrupted, result.problems)
    print(paint(verdict, verdict, colour) + line[len(verdict):], flush=True)
    return verdict_status(verdict, lost=lost, interrupted=result.interrupted,
                          accept_incomplete=accept_incomplete)
