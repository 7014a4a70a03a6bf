"""The units a run tested, for the top of the HTML page: one row each (profile, the
firmware's `?` and `Q` answers, the motion envelope, the largest excursion, the verdict)
and, for each real unit, its state as the session found it and as it left it (what was
put back, what was set to the reset state, what could not be)."""

from __future__ import annotations

from conformance.reports.banner import run_verdict
from conformance.reports.text import html_text as h
from conformance.runner import RunResult
from conformance.targetinfo import EMULATOR

HEADERS = ("target", "profile", "firmware (`?`)", "processor id (`Q`)",
           "motion envelope (full steps per axis)", "largest excursion (full steps)",
           "verdict")
#: what the emulator's columns say where a real unit's hold figures
FRESH_UNIT = "not tracked: every case starts a fresh emulated unit"


def excursion_text(session: dict | None, kind: str) -> str:
    """How far each axis went either way, as ``X -12..+1400, Y +0..+0``."""
    if kind == EMULATOR:
        return FRESH_UNIT
    if not session or not session.get("excursion"):
        return "not measured (the session did not run)"
    return ", ".join(f"{a} {lo:+g}..{hi:+g}" for a, (lo, hi)
                     in zip(session["axes"], session["excursion"], strict=False))


def units_table(run: RunResult) -> list[str]:
    out = ["<h2>Units</h2><table class='units'><tr>"
           + "".join(f"<th>{h(x)}</th>" for x in HEADERS) + "</tr>"]
    for target in run.targets:
        t = run.meta.target(target)
        v, why = run_verdict(run, target)
        envelope = (f"±{t.envelope}" if t.envelope is not None else
                    "none (the emulator: nothing to protect)" if t.kind == EMULATOR
                    else "not enforced")
        chosen = f" ({t.profile_chosen})" if t.profile_chosen else ""
        cells = (target, f"{t.profile}{chosen}", t.version or "(not read)",
                 t.processor_id or "(not read)", envelope,
                 excursion_text(run.sessions.get(target), t.kind))
        out.append("<tr>" + "".join(f"<td>{h(c)}</td>" for c in cells)
                   + f"<td class='{h(v)}'>{h(v)}: {h(why)}</td></tr>")
    out.append("</table>")
    return out


def _found(s: dict) -> list[str]:
    ident = s.get("identity") or {}
    out = [*((f"firmware (`?`): {ident['version']}",) if "version" in ident else ()),
           *((f"processor id (`Q`): {ident['processor_id']}",)
             if "processor_id" in ident else ())]
    found = dict(s.get("found") or {})
    words = [f"{k} {found.pop(k)}" for k in [k for k in found if k.startswith("ST")]]
    if words:
        out.append("status words: " + ", ".join(words))
    out += [f"{k}: {v}" for k, v in found.items()]
    return out


def _left(s: dict) -> list[tuple[str, str]]:
    """(class, line): what the session put back, set, and could not put back."""
    out = [("PASS", f"restored: {r}") for r in s.get("restored", [])]
    out += [("", f"reset: {r}") for r in s.get("reset", [])]
    if s.get("not_responding"):
        out.append(("FAIL", s["not_responding"]))
    if s.get("interrupted"):
        out.append(("FAIL", "interrupted by a signal: H and D sent"))
    out += [("FAIL", f"PROBLEM: {p}") for p in s.get("problems", [])]
    return out


def _items(lines: list[tuple[str, str]], empty: str) -> str:
    if not lines:
        return f"<p class='why'>{h(empty)}</p>"
    return "<ul>" + "".join(f"<li class='{h(c)}'>{h(text)}</li>" if c else
                            f"<li>{h(text)}</li>" for c, text in lines) + "</ul>"


def state_section(run: RunResult) -> list[str]:
    """Every unit's state as found and as left, in plain view."""
    if not run.sessions:
        return []
    out = ["<h2 id='state'>The units as found and as left</h2>"]
    emulated = [t for t, s in run.sessions.items() if not s.get("real")]
    for target, s in run.sessions.items():
        if not s.get("real"):
            continue
        out.append(f"<table class='state'><tr><th colspan='2'>{h(target)} "
                   f"({h(s.get('profile', ''))})</th></tr>"
                   "<tr><th>as found (before the first case)</th>"
                   "<th>as left (after the last case)</th></tr><tr><td>"
                   + _items([("", x) for x in _found(s)], "nothing read: the session did "
                            "not begin")
                   + "</td><td>" + _items(_left(s), "nothing to put back")
                   + "</td></tr>")
        if s.get("violations"):
            out.append("<tr><th colspan='2'>answers between the cases</th></tr><tr>"
                       "<td colspan='2'>" + _items([("FAIL", v) for v in s["violations"]],
                                                   "") + "</td></tr>")
        out.append("</table>")
    if emulated:
        out.append(f"<p>{h(', '.join(emulated))}: the embedded emulator — every case ran "
                   "on a fresh unit, so there was nothing to find on it and nothing to put "
                   "back.</p>")
    return out
