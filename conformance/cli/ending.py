"""What every job of `gve-conformance` prints and how it ends: a run's ID, one line per
result as it comes, the verdicts counted, the reports written, the exit status (0 when
the verdict line says PASSED, else 1)."""

from __future__ import annotations

import time
import uuid
from collections.abc import Callable
from pathlib import Path

from conformance.cli.usage import exit_status
from conformance.reports import write_reports
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


def end(result: RunResult, report_dir: str | Path | None, *, quiet: bool = False) -> int:
    """Write the reports (unless ``report_dir`` is None) and say where, then the verdict
    line (what was judged, what was not tested and why); the exit status: 0 for
    PASSED, 1 otherwise, 130 when a signal stopped the job."""
    if report_dir is not None:
        folder = write_reports(result, report_dir)
        if not quiet:
            print(f"reports: {folder}/junit.xml, results.json, report.html")
    print(last_line(result.results, result.interrupted, result.problems), flush=True)
    verdict, _ = overall(result.results, result.interrupted, result.problems)
    return exit_status(verdict == PASSED, result.interrupted)
