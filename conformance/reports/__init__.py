"""Run reports: JUnit XML, JSON and one self-contained HTML page (issue 4 item 8)."""

from __future__ import annotations

import json
from pathlib import Path

from conformance.reports.html import render_html
from conformance.reports.junit import render_junit
from conformance.runner import RunResult


def write_reports(run: RunResult, folder: str | Path) -> Path:
    out = Path(folder) / run.run_id
    out.mkdir(parents=True, exist_ok=True)
    (out / "junit.xml").write_text(render_junit(run), encoding="utf-8")
    (out / "results.json").write_text(json.dumps(to_json(run), indent=1), encoding="utf-8")
    (out / "report.html").write_text(render_html(run), encoding="utf-8")
    return out


def to_json(run: RunResult) -> dict:
    return {"run_id": run.run_id, "targets": run.targets, "settings": run.settings,
            "seconds": round(run.seconds, 3), "frames": run.frames,
            "interrupted": run.interrupted, "counts": run.counts(),
            "problems": run.problems, "sessions": run.sessions,
            "results": [r.to_dict() for r in run.results]}
