"""Run reports (issue 12): JUnit XML, JSON and one self-contained HTML page, written per
run into ``<folder>/<run id>/``. ``write_reports(run, folder) -> Path`` is the one entry
point (the suite's run, host certification and fleets call it per target or per run)."""

from __future__ import annotations

import json
from pathlib import Path

from conformance.reports.html import render_html
from conformance.reports.junit import render_junit, write_junit
from conformance.reports.logs import compact, compact_checks
from conformance.reports.sections import section_name
from conformance.runner import RunResult
from conformance.verdict import overall

__all__ = ["render_html", "render_junit", "to_json", "write_junit", "write_reports"]


def write_reports(run: RunResult, folder: str | Path) -> Path:
    out = Path(folder) / run.run_id
    out.mkdir(parents=True, exist_ok=True)
    write_junit(run, out / "junit.xml")
    (out / "results.json").write_text(json.dumps(to_json(run)), encoding="utf-8")
    (out / "report.html").write_text(render_html(run), encoding="utf-8")
    return out


def to_json(run: RunResult) -> dict:
    """The run as data: the same metadata and overall verdict as the page, every result
    with its wire log as the page shows it (``wire_log_lines``: the whole log's length)."""
    verdict, reason = overall([r.verdict for r in run.results], run.interrupted)
    results = []
    for r in run.results:
        d = r.to_dict()
        d["section_name"] = section_name(r.section)
        d["wire_log_lines"] = len(r.wire_log)
        d["wire_log"] = compact(r.wire_log, r.verdict, run.meta.full_logs)
        d["checks_total"] = len(r.checks)
        d["checks"] = compact_checks(r.checks, run.meta.full_logs)
        results.append(d)
    return {"verdict": verdict, "reason": reason, "run_id": run.run_id,
            "meta": run.meta.to_dict(), "targets": run.targets, "settings": run.settings,
            "seconds": round(run.seconds, 3), "frames": run.frames,
            "interrupted": run.interrupted, "counts": run.counts(), "results": results}
