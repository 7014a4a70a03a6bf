"""One self-contained HTML page: the banner PASSED/FAILED and, right
under it, what failed (each failing case with the check that failed it, linked to the
case); then the run's metadata, the units (as found and as left), bars and a matrix of
verdicts by spec section (cells link to the cases), filters (a little inline script:
works offline), and per case its checks, pictures of its motion (the fault marked), notes
and wire log. No external assets.

The page is rendered from the Jinja2 templates in ``templates/`` with autoescaping on:
every value a template shows is escaped, and first cleaned of the characters HTML cannot
carry (:func:`conformance.reports.text.clean`), unless this module marked it as markup
(a rule's sentence set as HTML, the charts, the page's own style and script). Nothing a
target sent needs an escape call placed by hand: this module prepares data, the
templates lay it out."""

from __future__ import annotations

import shlex
from collections import Counter
from dataclasses import dataclass, field
from functools import cache
from importlib import resources

from jinja2 import Environment, PackageLoader, StrictUndefined
from markupsafe import Markup

import conformance.reports.plots as plots
from conformance.reports.banner import run_verdict
from conformance.reports.failures import failures, natural
from conformance.reports.logs import compact, compact_checks
from conformance.reports.sections import section_key, section_title
from conformance.reports.text import clean, rule_html
from conformance.reports.unit_rows import units_view
from conformance.run.runner import CaseResult, RunResult
from conformance.verdicts.quoting import quoted
from conformance.verdicts.verdict import COULD_NOT_TEST, ERROR, FAIL, MISSING, ORDER, PASS

#: verdicts whose case opens by itself
_OPEN = (FAIL, ERROR)
#: verdicts whose reason (the first note) shows on the case's line
_WHY = (COULD_NOT_TEST, MISSING, ERROR)
#: verdicts that say the target could not be judged (counted under the failures)
_UNJUDGED = (COULD_NOT_TEST,)
#: the traces a passing case draws (the rest: --full-logs)
PASSING_PLOTS = 3


def _shown(value: object) -> object:
    """Every value a template prints: cleaned of what HTML cannot carry (autoescaping
    escapes it after); markup this module made is cleaned too and stays markup."""
    if isinstance(value, Markup):
        return Markup(clean(value))
    return clean(value)


def _anchor(r: CaseResult) -> str:
    return f"case-{r.id}-{r.profile}"


def _cell(check: dict, key: str) -> str:
    """A check's observed or expected value, quoted as on the console; a passing check
    with none shows nothing rather than "(nothing)"."""
    return quoted(check[key]) if check[key] or not check["ok"] else ""


@cache
def _templates() -> Environment:
    env = Environment(loader=PackageLoader("conformance.reports", "templates"),
                      autoescape=True, finalize=_shown, undefined=StrictUndefined,
                      trim_blocks=True, lstrip_blocks=True, keep_trailing_newline=False)
    env.filters.update(anchor=_anchor, cell=_cell, quoted=quoted,
                       rule=lambda text: Markup(rule_html(text)))
    return env


def _asset(name: str) -> Markup:
    """The page's own style or script (ours, not a target's: not escaped)."""
    return Markup(resources.files("conformance.reports").joinpath(name).read_text("utf-8"))


@dataclass
class _Section:
    key: str
    title: str
    counts: list[tuple[str, int]]
    cases: list[_Case] = field(default_factory=list)


@dataclass
class _Case:
    """One case run as the page shows it; ``also``: the other profiles on which the same
    case passed too (shown once, as its run on ``result.profile``)."""

    result: CaseResult
    full_logs: bool
    also: tuple[str, ...] = ()

    @property
    def profiles(self) -> tuple[str, ...]:
        return (self.result.profile, *self.also)

    @property
    def open(self) -> bool:
        return self.result.verdict in _OPEN

    @property
    def why(self) -> str | None:
        r = self.result
        return r.notes[0] if r.verdict in _WHY and r.notes else None

    @property
    def checks(self) -> list[dict]:
        return compact_checks(self.result.checks, self.result.verdict, self.full_logs)

    @property
    def wire_log(self) -> list[str]:
        return compact(self.result.wire_log, self.result.verdict, self.full_logs)

    def _shown_traces(self) -> list[dict]:
        r = self.result
        return r.traces if self.full_logs or r.verdict != PASS else r.traces[:PASSING_PLOTS]

    @property
    def pictures(self) -> list[dict]:
        """The case's traces drawn (for a passing case the position only and its first
        few traces: the report must stay small; --full-logs draws the rate and every
        one); ``svg`` None where plots are off."""
        r, rate = self.result, self.full_logs or self.result.verdict != PASS
        out = []
        for i, trace in enumerate(self._shown_traces()):
            key = f"{_anchor(r)}-{i}"
            if "pulses" in trace:
                svg = plots.step_train_chart(trace["pulses"], trace.get("axes", "XYZA"), key,
                                             trace.get("total"))
            else:
                svg = plots.trace_chart(trace, key, rate=rate)
            out.append({"svg": Markup(svg) if svg else None,
                        "name": trace.get("name", "trace")})
        return out

    @property
    def more_traces(self) -> int:
        return len(self.result.traces) - len(self._shown_traces())


def _meta(run: RunResult) -> list[tuple[str, object]]:
    m = run.meta
    return [("started", m.started), ("finished", m.finished),
            ("operator", m.operator or "(not given: --operator-name)"),
            ("suite version", m.suite_version),
            ("host", f"{m.host} ({m.platform}, Python {m.python})"),
            ("command", shlex.join(["gve-conformance", *m.command])),
            *m.flags().items()]


def _sections(run: RunResult, full: bool) -> list[_Section]:
    out = []
    for s in sorted({r.section for r in run.results}, key=section_key):
        counted = Counter(r.verdict for r in run.results if r.section == s)
        section = _Section(s, section_title(s), [(v, counted.get(v, 0)) for v in ORDER])
        results = sorted((r for r in run.results if r.section == s),
                         key=lambda r: (ORDER.index(r.verdict), r.id))
        # the report must stay small: a case passing on several profiles shows once
        passed: dict[str, list[CaseResult]] = {}
        for r in results:
            if r.verdict == PASS and not full:
                passed.setdefault(r.id, []).append(r)
            else:
                section.cases.append(_Case(r, full))
        section.cases += [_Case(first, full, tuple(o.profile for o in others))
                          for first, *others in passed.values()]
        out.append(section)
    return out


def _bars(sections: list[_Section]) -> list[dict]:
    """Per section, a bar of its case runs stacked by verdict, as wide as its share of the
    largest section's (drawn by the page itself: no plotting library needed)."""
    largest = max((sum(n for _, n in s.counts) for s in sections), default=0) or 1
    return [{"key": s.key, "title": s.title,
             "width": round(100 * sum(n for _, n in s.counts) / largest, 1),
             "parts": [(v, n) for v, n in s.counts if n]} for s in sections]


def _coverage(run: RunResult) -> dict | None:
    """Which rules of the spec the run's cases can fail, per section and profile."""
    report = run.meta.coverage
    if not report:
        return None
    cells: dict[str, dict[str, str]] = {}
    uncovered: dict[str, list[str]] = {}
    for pc in report:
        for s in pc["sections"]:
            total = s["covered"] + len(s["uncovered"])
            cells.setdefault(s["section"], {})[pc["profile"]] = f"{s['covered']}/{total}"
            for rule in s["uncovered"]:
                uncovered.setdefault(rule, []).append(pc["profile"])
    profiles = [pc["profile"] for pc in report]
    return {"profiles": profiles,
            "rows": [(section_title(s), [cells[s].get(p, "") for p in profiles])
                     for s in sorted(cells, key=section_key)],
            "totals": [f"{pc['covered']}/{pc['total']}" for pc in report],
            "uncovered": sorted(uncovered.items(), key=lambda kv: natural(kv[0])),
            "matrix": _matrix_rows(report)}


def _matrix_rows(report: list[dict]) -> dict | None:
    """The matrix diff runs, per model: cells run of all, observers read after each,
    state x command x observer reads, status-bit clauses with a cell; and what is left
    out (a state or form the model has not is meaningless there)."""
    shown = [pc for pc in report if pc.get("matrix")]
    if not shown:
        return None
    rows = [("cells (state x command form) run", lambda m: f"{m['run']}/{m['cells']}"),
            ("observers read after each", lambda m: str(m["observers"])),
            ("state x command x observer reads", lambda m: str(m["read"])),
            ("status-bit clauses of [M] rules with a cell",
             lambda m: f"{m['clauses'] - len(m['lacking']) - len(m['meaningless'])}"
                       f"/{m['clauses']}")]
    notes = []
    for pc in shown:
        m = pc["matrix"]
        for why, names in sorted(m["left_out"].items()):
            kind = "meaningless" if why.startswith("the ") else "not run"
            notes.append(f"{pc['profile']}: {len(names)} cell(s) {kind} ({why})")
        notes += [f"{pc['profile']}: no cell can fail {c}" for c in m["lacking"]]
        notes += [f"{pc['profile']}: meaningless on the model: {c}" for c in m["meaningless"]]
    return {"profiles": [pc["profile"] for pc in shown],
            "rows": [(title, [value(pc["matrix"]) for pc in shown]) for title, value in rows],
            "notes": notes}


def render_html(run: RunResult, full_logs: bool | None = None) -> str:
    full = run.meta.full_logs if full_logs is None else full_logs
    verdict, reason = run_verdict(run)
    counts = run.counts()
    sections = _sections(run, full)
    return _templates().get_template("report.html.j2").render(
        run=run, verdict=verdict, reason=reason, css=_asset("report.css"),
        js=_asset("report.js"), verdicts=ORDER,
        counts=[(v, counts[v]) for v in ORDER if v in counts], meta=_meta(run),
        failed=failures(run),
        untested=[f"{counts[v]} {v}" for v in _UNJUDGED if counts.get(v)],
        units=units_view(run), bars=_bars(sections),
        plots_off=any(r.traces for r in run.results) and not plots.available(),
        sections=sections,
        coverage=_coverage(run))
