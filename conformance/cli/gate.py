"""How a gate ends (`mutation`, `fairness`, `corpus`: items judged one at a time by
workers, cli/pool.py), as every job ends: what failed listed again, the reports written
(``--report-dir``, ``--junitxml``: reports/gate.py) and where, then the one last line.

- ``FAILED — ...`` when an item failed the gate (the score so far, whatever stopped it);
- a signal: ``FAILED — <job> interrupted by a signal after ...: no score``, exit status
  INTERRUPTED;
- the time limit (``--seconds``) with nothing failed: ``INCOMPLETE — <job>: the time
  limit of S s came after N of M <items>...``, exit status INCOMPLETE_STATUS (0 with
  ``--accept-incomplete``): a score of what was not all tried is not a pass;
- else ``PASSED — <score>``.
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Sequence
from pathlib import Path

from conformance.cli.ending import claimed, written
from conformance.cli.usage import INTERRUPTED, verdict_status, writable_folder
from conformance.reports.gate import GateItem, GateRun, write_gate_junit, write_gate_reports
from conformance.run.metadata import now_iso
from conformance.verdicts.verdict import FAILED, INCOMPLETE, PASSED

__all__ = ["Gate", "GateItem", "under_way"]


def under_way(jobs: int, total: int, finished: int) -> int:
    """How many items a pool of ``jobs`` workers had begun and not finished when it
    was stopped."""
    return min(jobs, total - finished)


def _many(n: int, noun: str) -> str:
    """``1 mutant``, ``2 mutants``."""
    return f"{n} {noun}" if n == 1 else f"{n} {noun}s"


class Gate:
    """One gate's run from its parsed ``args`` (the shared job options: cli/usage.py):
    its report folder taken before anything runs (UsageError when it cannot be), then
    :meth:`end`."""

    def __init__(self, job: str, args: argparse.Namespace, argv: Sequence[str]) -> None:
        self.job, self.args, self.command = job, args, [job, *argv]
        self.started, self.start = now_iso(), time.perf_counter()
        self.folder: Path | None = None
        if not args.no_reports:
            writable_folder(args.report_dir)
            self.folder = claimed(args.report_dir, args.run_id)

    def end(self, items: Sequence[GateItem], not_run: Sequence[str], noun: str, score: str,
            *, interrupted: bool, timed_out: bool, under_way: int = 0,
            failed_word: str = "failed") -> int:
        """The end (see the module's text): ``items`` judged, ``not_run`` the names of
        those the job did not finish, ``noun`` what an item is (``mutant``), ``score``
        the score line of what was judged, ``failed_word`` what a failed item is called
        (``unfair``). The exit status."""
        failed = [item for item in items if not item.passed]
        if failed:
            print(f"what failed ({len(failed)} {noun}(s)):", flush=True)
            for item in failed:
                for line in item.lines:
                    print(line, flush=True)
        elapsed = time.perf_counter() - self.start
        total = len(items) + len(not_run)
        if interrupted:
            verdict, reason = FAILED, (
                f"{self.job} interrupted by a signal after {len(items)} of "
                f"{_many(total, noun)} finished ({len(failed)} {failed_word}; {under_way} "
                f"under way) in {elapsed:.1f} s: no score")
        elif failed:
            verdict, reason = FAILED, score
        elif timed_out:
            verdict, reason = INCOMPLETE, (
                f"{self.job}: the time limit of {self.args.seconds:g} s came after "
                f"{len(items)} of {_many(total, noun)}; not tested: "
                f"{_many(len(not_run), noun)}; so far {score}")
        else:
            verdict, reason = PASSED, score
        lost = self._reports(items, not_run, verdict, reason, elapsed)
        print(f"{verdict} — {reason}", flush=True)
        if interrupted:
            return INTERRUPTED
        return verdict_status(verdict, lost=lost,
                              accept_incomplete=self.args.accept_incomplete)

    def _reports(self, items: Sequence[GateItem], not_run: Sequence[str], verdict: str,
                 reason: str, elapsed: float) -> bool:
        """The reports written and where they are said; True when one was lost."""
        why = "not run: the job ended before it"
        run = GateRun(self.job, self.folder.name if self.folder else "", verdict, reason,
                      [*items, *(GateItem(n, None, 0.0, [why]) for n in not_run)],
                      elapsed, self.command, self.started)
        lost = False
        if self.folder is not None:
            folder = written(lambda: write_gate_reports(run, self.folder.parent))
            lost = folder is None
            if folder is not None:
                print(f"reports: {folder}/results.json, junit.xml", flush=True)
        if self.args.junitxml:
            junit = written(lambda: write_gate_junit(run, self.args.junitxml))
            lost = lost or junit is None
            if junit is not None:
                print(f"JUnit XML: {junit}", flush=True)
        return lost
