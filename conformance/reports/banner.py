"""The banner of every report: PASSED or FAILED for the run, or for one of its targets."""

from __future__ import annotations

from conformance.run.runner import RunResult
from conformance.verdicts.verdict import overall


def run_verdict(run: RunResult, target: str | None = None) -> tuple[str, str]:
    """PASSED or FAILED, and why, for the whole run or for ``target`` alone."""
    if target is None:
        return overall(run.results, run.interrupted, run.problems)
    session = run.sessions.get(target) or {}
    return overall([r for r in run.results if r.target == target], run.interrupted,
                   session.get("problems", []))
