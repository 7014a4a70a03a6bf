"""One self-contained HTML page: the banner PASSED/FAILED and, right
under it, what failed (each failing case with the check that failed it, linked to the
case); then the run's metadata, the units (as found and as left), a chart and a matrix of
verdicts by spec section (cells link to the cases), filters (a little inline script:
works offline), and per case its checks, pictures of its motion (the fault marked), notes
and wire log. No external assets; every text from a unit goes through :func:`html_text`."""

from __future__ import annotations

import shlex
from collections import Counter
from importlib import resources

import conformance.reports.plots as plots
from conformance.quoting import quoted
from conformance.reports.banner import run_verdict
from conformance.reports.failures import failures
from conformance.reports.logs import compact, compact_checks
from conformance.reports.sections import section_key, section_title
from conformance.reports.text import html_text as h
from conformance.reports.text import rule_html
from conformance.reports.units import state_section, units_table
from conformance.runner import CaseResult, RunResult
from conformance.verdict import COULD_NOT_TEST, ERROR, FAIL, MISSING, ORDER, PASS

#: verdicts whose case opens by itself
_OPEN = (FAIL, ERROR)
#: verdicts whose reason (the first note) shows on the case's line
_WHY = (COULD_NOT_TEST, MISSING, ERROR)
#: verdicts that say the target could not be judged (counted under the failures)
_UNJUDGED = (COULD_NOT_TEST,)


def _asset(name: str) -> str:
    return resources.files("conformance.reports").joinpath(name).read_text("utf-8")


def _anchor(r: CaseResult) -> str:
    return f"case-{r.id}-{r.profile}"


def _rows(items: list[tuple[str, object]]) -> str:
    return "".join(f"<tr><th>{h(k)}</th><td>{h(v)}</td></tr>" for k, v in items)


def _header(run: RunResult) -> list[str]:
    verdict, reason = run_verdict(run)
    m = run.meta
    counts = run.counts()
    return [f"<div class='banner {verdict}'>{verdict}</div> <span class='why'>{h(reason)}"
            f"{' (interrupted by Ctrl-C)' if run.interrupted else ''}</span>",
            *([f"<ul class='FAIL'>{''.join(f'<li>PROBLEM: {h(p)}</li>' for p in run.problems)}"
               "</ul>"] if run.problems else []),
            *_failed(run),
            f"<h1>gve-conformance run {h(run.run_id)}</h1>",
            "<p>" + " ".join(f"<span class='{h(v)}'>{h(v)}: {counts[v]}</span>"
                             for v in ORDER if v in counts)
            + f" — {len(run.results)} case runs in {run.seconds:.1f} s, {run.frames} frames</p>",
            "<table class='meta'>" + _rows([
                ("started", m.started), ("finished", m.finished),
                ("operator", m.operator or "(not given: --operator-name)"),
                ("suite version", m.suite_version),
                ("host", f"{m.host} ({m.platform}, Python {m.python})"),
                ("command", shlex.join(["gve-conformance", *m.command])),
                *((flag, value) for flag, value in m.flags().items())]) + "</table>",
            *units_table(run), *state_section(run)]


def _failed(run: RunResult) -> list[str]:
    """The failing cases, right under the banner: each with the check that failed it,
    linked to the case below."""
    found = failures(run)
    counts = run.counts()
    untested = [f"{counts[v]} {v}" for v in _UNJUDGED if counts.get(v)]
    if not found and not untested:
        return []
    out = [f"<section id='failed'><h2>What failed ({len(found)})</h2>" if found else
           "<section id='failed'><h2>What failed: no case</h2>"]
    if found:
        out.append("<table class='failed'><tr><th>case</th><th>what failed</th>"
                   "<th>observed</th><th>expected</th><th>rule</th></tr>")
        for f in found:
            profiles = h(f.runs[0].profile) if len(f.runs) == 1 else ", ".join(
                f"<a href='#{h(_anchor(r))}'>{h(r.profile)}</a>" for r in f.runs)
            why = f.why
            seen = (f"<td>{h(quoted(why.observed))}</td><td>{h(quoted(why.expected))}</td>"
                    if why.checked else "<td></td><td></td>")
            rule = (f"<b>{h(why.head())}</b> " if why.checked else "") + (
                f"<q>{rule_html(why.rule)}</q>" + (f" ({h(why.source)})" if why.source
                                                   else "")
                if why.rule else "")
            out.append(f"<tr class='{h(f.verdict)}'><td><a href='#{h(_anchor(f.runs[0]))}'>"
                       f"<b>{h(f.verdict)}</b> {h(f.id)}</a> [{profiles}]</td>"
                       f"<td>{h(why.what)}</td>{seen}<td>{rule}</td></tr>")
        out.append("</table>")
    if untested:
        out.append(f"<p class='why'>Not judged: {h(', '.join(untested))} (each says why on "
                   "its line under Cases).</p>")
    out.append("</section>")
    return out


def _matrix(run: RunResult, sections: list[str]) -> list[str]:
    by_section = {s: Counter(r.verdict for r in run.results if r.section == s)
                  for s in sections}
    chart = plots.verdict_chart([(section_title(s), by_section[s]) for s in sections])
    out = ["<h2>Verdicts by spec section</h2>",
           f"<figure>{chart}</figure>" if chart else
           "<p class='why'>Plots are off: install the suite with its <code>[plots]</code> "
           "extra (e.g. <code>pip install './gve-conformance[plots]'</code>) to draw them.</p>",
           "<table><tr><th>section</th>",
           *(f"<th class='{h(v)}'>{h(v)}</th>" for v in ORDER), "</tr>"]
    for s in sections:
        out.append(f"<tr><td><a href='#sec-{h(s)}' data-section='{h(s)}' data-verdict=''>"
                   f"{h(section_title(s))}</a></td>")
        for v in ORDER:
            n = by_section[s].get(v, 0)
            out.append(f"<td class='n'><a href='#sec-{h(s)}' data-section='{h(s)}' "
                       f"data-verdict='{h(v)}'>{n}</a></td>" if n else "<td></td>")
        out.append("</tr>")
    out.append("</table>")
    return out


def _coverage(run: RunResult) -> list[str]:
    """Which rules of the spec the run's cases can fail, per section and profile."""
    report = run.meta.coverage
    if not report:
        return []
    cells: dict[str, dict[str, str]] = {}
    uncovered: dict[str, list[str]] = {}
    for pc in report:
        for s in pc["sections"]:
            total = s["covered"] + len(s["uncovered"])
            cells.setdefault(s["section"], {})[pc["profile"]] = f"{s['covered']}/{total}"
            for rule in s["uncovered"]:
                uncovered.setdefault(rule, []).append(pc["profile"])
    profiles = [pc["profile"] for pc in report]
    out = ["<h2>Coverage: rules of the spec the cases can fail</h2><table><tr><th>section</th>",
           *(f"<th>{h(p)}</th>" for p in profiles), "</tr>"]
    for s in sorted(cells, key=section_key):
        out.append(f"<tr><td>{h(section_title(s))}</td>"
                   + "".join(f"<td class='n'>{h(cells[s].get(p, ''))}</td>" for p in profiles)
                   + "</tr>")
    out.append("<tr><th>all</th>" + "".join(f"<th class='n'>{pc['covered']}/{pc['total']}</th>"
                                           for pc in report) + "</tr></table>")
    if uncovered:
        out.append("<details><summary>Rules no selected case can fail "
                   f"({len(uncovered)})</summary><ul>"
                   + "".join(f"<li>{h(rule)}: {h(', '.join(ps))}</li>"
                             for rule, ps in sorted(uncovered.items())) + "</ul></details>")
    return out


def _filters(sections: list[str]) -> str:
    boxes = "".join(f"<label class='{h(v)}'><input type='checkbox' value='{h(v)}' checked> "
                    f"{h(v)}</label>" for v in ORDER)
    options = "".join(f"<option value='{h(s)}'>{h(section_title(s))}</option>"
                      for s in sections)
    return (f"<div id='filters'>{boxes} <select id='f-section'><option value=''>"
            f"every section</option>{options}</select> <input id='f-text' type='search' "
            "placeholder='case ID contains'></div>")


#: the traces a passing case draws (the rest: --full-logs)
PASSING_PLOTS = 3


def _pictures(r: CaseResult, full_logs: bool) -> list[str]:
    """The case's traces drawn (for a passing case the position only and its first few
    traces: the report must stay small; --full-logs draws the rate and every one)."""
    out = []
    shown = r.traces if full_logs or r.verdict != PASS else r.traces[:PASSING_PLOTS]
    for i, trace in enumerate(shown):
        key = f"{_anchor(r)}-{i}"
        if "pulses" in trace:
            svg = plots.step_train_chart(trace["pulses"], trace.get("axes", "XYZA"), key,
                                         trace.get("total"))
        else:
            svg = plots.trace_chart(trace, key, rate=full_logs or r.verdict != PASS)
        out.append(f"<figure>{svg}</figure>" if svg else
                   f"<p class='why'>{h(trace.get('name', 'trace'))}: plots are off.</p>")
    if len(shown) < len(r.traces):
        out.append(f"<p class='why'>... {len(r.traces) - len(shown)} more traces passed "
                   "(all of them drawn: --full-logs) ...</p>")
    return out


def _case(r: CaseResult, full_logs: bool, also: tuple[str, ...] = ()) -> list[str]:
    """One case run; ``also``: the other profiles on which the same case passed too
    (shown once, as its run on ``r.profile``)."""
    why = f" <span class='why'>— {h(r.notes[0])}</span>" if r.verdict in _WHY and r.notes \
        else ""
    profiles = ", ".join((r.profile, *also))
    out = [f"<details class='case {h(r.verdict)}' id='{h(_anchor(r))}' "
           f"data-verdict='{h(r.verdict)}' data-section='{h(r.section)}'"
           f"{' open' if r.verdict in _OPEN else ''}>"
           f"<summary><b>{h(r.verdict)}</b> {h(r.id)} [{h(profiles)}] — {rule_html(r.rule)}"
           f"{why}"
           "</summary>",
           *([f"<p class='why'>Passed on {len(also) + 1} profiles; shown: its run on "
              f"{h(r.profile)} (each run apart: --full-logs).</p>"] if also else []),
           f"<p>Tag {h(r.tag)}, source {h(r.source)}, target {h(r.target)}, {r.seconds:.3f} s, "
           f"{r.frames} frames.</p>"]
    if r.checks:
        out.append("<table><tr><th>ok</th><th>check</th><th>tag</th><th>observed</th>"
                   "<th>expected</th></tr>")
        out += [f"<tr class='{'PASS' if c['ok'] else 'FAIL'}'><td>{'yes' if c['ok'] else 'NO'}"
                f"</td><td>{h(c['what'])}</td><td>{h(c['tag'])}</td>"
                f"<td>{h(_cell(c, 'observed'))}</td><td>{h(_cell(c, 'expected'))}</td></tr>"
                for c in compact_checks(r.checks, r.verdict, full_logs)]
        out.append("</table>")
    out += _pictures(r, full_logs)
    out += [f"<pre>{h(n)}</pre>" for n in r.notes]
    if r.wire_log:
        out.append("<pre>" + h("\n".join(compact(r.wire_log, r.verdict, full_logs))) + "</pre>")
    for name, text in r.artifacts.items():
        out.append(f"<p>{h(name)}</p><pre>{h(text)}</pre>")
    out.append("</details>")
    return out


def render_html(run: RunResult, full_logs: bool | None = None) -> str:
    full = run.meta.full_logs if full_logs is None else full_logs
    verdict, _ = run_verdict(run)
    sections = sorted({r.section for r in run.results}, key=section_key)
    out = ["<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>",
           f"<title>{verdict} — gve-conformance {h(run.run_id)}</title>",
           f"<style>{_asset('report.css')}</style></head><body>",
           *_header(run), *_matrix(run, sections), *_coverage(run),
           "<h2 id='cases'>Cases</h2>", _filters(sections)]
    for s in sections:
        out.append(f"<section class='cases' id='sec-{h(s)}'><h3>{h(section_title(s))}</h3>")
        results = sorted((r for r in run.results if r.section == s),
                         key=lambda r: (ORDER.index(r.verdict), r.id))
        # the report must stay small: a case passing on several profiles shows once
        passed: dict[str, list[CaseResult]] = {}
        for r in results:
            if r.verdict == PASS and not full:
                passed.setdefault(r.id, []).append(r)
            else:
                out += _case(r, full)
        for first, *others in passed.values():
            out += _case(first, full, tuple(o.profile for o in others))
        out.append("</section>")
    out.append(f"<script>{_asset('report.js')}</script></body></html>")
    return "\n".join(out)


def _cell(check: dict, key: str) -> str:
    """A check's observed or expected value, quoted as on the console; a passing check
    with none shows nothing rather than "(nothing)"."""
    return quoted(check[key]) if check[key] or not check["ok"] else ""
