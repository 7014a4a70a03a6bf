"""One self-contained HTML page: summary matrix (section × verdict), target and profile,
and per case its verdict, rule, section, checks and full wire log. No external assets."""

from __future__ import annotations

from html import escape

from conformance.reports.clean import clean
from conformance.runner import RunResult
from conformance.verdict import ORDER

STYLE = """
body{font:14px system-ui,sans-serif;margin:1.5em;color:#222}
table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #ccc;padding:2px 8px}
.PASS{background:#d8f5d0}.FAIL,.ERROR{background:#f8c9c4}.NON-STRICT{background:#fbe8b0}
.INFO{background:#dde8fb}.MISSING,.COULD-NOT-TEST{background:#eee}
details{margin:.3em 0;border-left:4px solid #ccc;padding-left:.5em}
pre{background:#f6f6f6;padding:.5em;overflow:auto;max-height:30em}
summary{cursor:pointer}
"""


def _cls(v: str) -> str:
    return escape(v)


def _sessions(run: RunResult) -> list[str]:
    """Per real unit: the envelope, the largest excursion, what was put back."""
    out = []
    for spec, s in run.sessions.items():
        if not s.get("real"):
            continue
        axes = ", ".join(f"{a} {lo:+g}..{hi:+g}" for a, (lo, hi)
                         in zip(s["axes"], s["excursion"] or [], strict=False))
        lines = [f"largest excursion (full steps, envelope ±{s['max_travel']}): {axes}",
                 *[f"restored: {r}" for r in s["restored"]],
                 *[f"reset: {r}" for r in s["reset"]]]
        out.append(f"<p><b>{escape(spec)}</b> {escape(str(s['identity']))}<br>"
                   + "<br>".join(escape(line) for line in lines) + "</p>")
    return out


def render_html(run: RunResult) -> str:
    counts = run.counts()
    sections = sorted({r.section for r in run.results},
                      key=lambda s: tuple(int(x) for x in s.split(".") if x.isdigit()))
    out = ["<!DOCTYPE html><html><head><meta charset='utf-8'>",
           f"<title>gve-conformance {escape(run.run_id)}</title><style>{STYLE}</style>",
           "</head><body>", f"<h1>gve-conformance run {escape(run.run_id)}</h1>",
           f"<p>Targets: {escape(', '.join(run.targets))}. Settings: {escape(run.settings)}. "
           f"{len(run.results)} cases in {run.seconds:.1f} s, {run.frames} frames"
           f"{' (interrupted)' if run.interrupted else ''}.</p>",
           *[f"<p class='FAIL'><b>PROBLEM</b>: {escape(p)}</p>" for p in run.problems],
           "<p>" + " ".join(f"<span class='{_cls(v)}'>{escape(v)}: {counts[v]}</span>"
                            for v in ORDER if v in counts) + "</p>",
           *_sessions(run),
           "<h2>Summary: spec section × verdict</h2><table><tr><th>section</th>"]
    out += [f"<th class='{_cls(v)}'>{escape(v)}</th>" for v in ORDER]
    out.append("</tr>")
    for s in sections:
        rs = [r for r in run.results if r.section == s]
        out.append(f"<tr><td>{escape(s)}</td>")
        out += [f"<td>{sum(r.verdict == v for r in rs) or ''}</td>" for v in ORDER]
        out.append("</tr>")
    out.append("</table><h2>Cases</h2>")
    for r in sorted(run.results, key=lambda r: ORDER.index(r.verdict)):
        out.append(f"<details class='{_cls(r.verdict)}'><summary><b>{escape(r.verdict)}</b> "
                   f"{escape(r.id)} [{escape(r.profile)}] — {escape(r.rule)}</summary>")
        out.append(f"<p>Section {escape(r.section)}, tag {escape(r.tag)}, source "
                   f"{escape(r.source)}, target {escape(r.target)}, {r.seconds:.3f} s.</p>")
        if r.checks:
            out.append("<table><tr><th>ok</th><th>check</th><th>tag</th><th>observed</th>"
                       "<th>expected</th></tr>")
            for c in r.checks:
                out.append(f"<tr class='{'PASS' if c['ok'] else 'FAIL'}'><td>"
                           f"{'yes' if c['ok'] else 'NO'}</td><td>{escape(c['what'])}</td>"
                           f"<td>{escape(c['tag'])}</td><td>{escape(c['observed'])}</td>"
                           f"<td>{escape(c['expected'])}</td></tr>")
            out.append("</table>")
        for n in r.notes:
            out.append(f"<pre>{escape(n)}</pre>")
        out.append("<pre>" + escape("\n".join(r.wire_log)) + "</pre>")
        for name, text in r.artifacts.items():
            out.append(f"<p>{escape(name)}</p><pre>{escape(text)}</pre>")
        out.append("</details>")
    out.append("</body></html>")
    return clean("\n".join(out))        # no raw control byte of a unit in the page
