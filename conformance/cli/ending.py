"""What every job of `gve-conformance` prints and how it ends: a run's ID and folder
(taken before the run: never another run's), one line per result as it comes, the
verdicts counted, the reports written (or one line saying which file could not be and
why: then the exit status is not 0), the exit status (0 when the verdict line says
PASSED, else 1)."""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path

from conformance.cli.usage import UsageError, exit_status
from conformance.reports import ReportNotWritten, write_reports
from conformance.reports.files import RunFolderTaken, claim, new_run_id
from conformance.runner import CaseResult, RunResult
from conformance.verdict import ORDER, PASSED, last_line, overall

__all__ = ["claimed", "counted", "end", "new_run_id", "progress", "written"]


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


def end(result: RunResult, report_dir: str | Path | None, *, quiet: bool = False) -> int:
    """Write the reports (unless ``report_dir`` is None) and say where, then the verdict
    line (what was judged, what was not tested and why); the exit status: 0 for
    PASSED, 1 otherwise, 130 when a signal stopped the job."""
    lost = False
    if report_dir is not None:
        folder = written(lambda: write_reports(result, report_dir))
        lost = folder is None
        if folder is not None and not quiet:
            print(f"reports: {folder}/junit.xml, results.json, report.html")
    print(last_line(result.results, result.interrupted, result.problems), flush=True)
    verdict, _ = overall(result.results, result.interrupted, result.problems)
    return exit_status(verdict == PASSED and not lost, result.interrupted)
