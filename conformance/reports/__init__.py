"""Run reports: JUnit XML, JSON and one self-contained HTML page, written per
run into ``<folder>/<run id>/``. ``write_reports(run, folder) -> Path`` is the one entry
point (the suite's run, host certification and fleets call it per target or per run);
each file is written whole or not at all, ReportNotWritten saying which could not be
(files.py)."""

from __future__ import annotations

import json
from dataclasses import fields
from pathlib import Path

from conformance.reports.banner import run_verdict
from conformance.reports.files import ReportNotWritten, write_text
from conformance.reports.junit import render_junit, write_junit
from conformance.reports.logs import compact, compact_checks, compact_traces
from conformance.reports.sections import section_key, section_name
from conformance.run.runner import RunResult

__all__ = ["ReportNotWritten", "render_junit", "to_json", "write_junit", "write_reports"]


def write_reports(run: RunResult, folder: str | Path) -> Path:
    # the page's template and plots are loaded only by a run that writes one: a command
    # that writes no report starts without them
    from conformance.reports.html import render_html

    out = Path(folder) / run.run_id
    write_junit(run, out / "junit.xml")
    write_text(out / "results.json", json.dumps(to_json(run), separators=(",", ":")))
    write_text(out / "report.html", render_html(run))
    return out


def to_json(run: RunResult) -> dict:
    """The run as data: the same metadata and overall verdict as the page, every result
    with its wire log and checks as the page shows them (``wire_log_lines``,
    ``checks_total``: how many there were); a check names its rule only where it is not
    the case's own. What a case is (rule, source, section name) is said once, in
    ``cases``, not in each of its runs."""
    verdict, reason = run_verdict(run)
    results = []
    for r in run.results:
        # shallow: the long lists are replaced by their compact forms below
        d = {f.name: getattr(r, f.name) for f in fields(r) if f.name not in ("rule", "source")}
        d["seconds"] = round(r.seconds, 4)
        d["wire_log_lines"] = len(r.wire_log)
        d["wire_log"] = compact(r.wire_log, r.verdict, run.meta.full_logs)
        d["checks_total"] = len(r.checks)
        d["checks"] = [{k: v for k, v in c.items() if k != "rule" or v != r.rule}
                       for c in compact_checks(r.checks, r.verdict, run.meta.full_logs,
                                                said=False)]
        d["traces_total"] = len(r.traces)
        d["traces"] = compact_traces(r.traces, r.verdict, run.meta.full_logs)
        results.append(d)
    return {"verdict": verdict, "reason": reason, "run_id": run.run_id,
            "meta": run.meta.to_dict(), "targets": run.targets, "settings": run.settings,
            "seconds": round(run.seconds, 3), "frames": run.frames,
            "interrupted": run.interrupted, "problems": run.problems,
            "sessions": run.sessions, "counts": run.counts(),
            "sections": {s: section_name(s) for s in sorted({r.section for r in run.results},
                                                            key=section_key)},
            "cases": {r.id: {"rule": r.rule, "tag": r.tag, "source": r.source,
                             "section": r.section} for r in run.results},
            "results": results}
