"""The units a run tested, for the top of the HTML page (as data: its template lays it
out): one row each (profile, the firmware's `?` and `Q` answers, the motion envelope, the
largest excursion, the verdict) and, for each real unit, its state as the session found
it and as it left it (what was put back, what was set to the reset state, what could
not be)."""

from __future__ import annotations

from conformance.reports.banner import run_verdict
from conformance.run.runner import RunResult
from conformance.targets.info import EMULATOR

HEADERS = ("target", "profile", "firmware (its answer to ?)",
           "processor id (its answer to Q)",
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


def _rows(run: RunResult) -> list[dict]:
    out = []
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
        out.append({"cells": cells, "verdict": v, "why": why})
    return out


def _found(s: dict) -> list[str]:
    ident = s.get("identity") or {}
    out = [*((f"firmware (its answer to ?): {ident['version']}",) if "version" in ident
             else ()),
           *((f"processor id (its answer to Q): {ident['processor_id']}",)
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


def units_view(run: RunResult) -> dict:
    """The units' table and every real unit's state as found and as left, as the page's
    template (templates/units.html.j2) lays them out."""
    states = [{"target": target, "profile": s.get("profile", ""),
               "found": [("", x) for x in _found(s)], "left": _left(s),
               "violations": [("FAIL", v) for v in s.get("violations", [])]}
              for target, s in run.sessions.items() if s.get("real")]
    return {"headers": HEADERS, "rows": _rows(run), "states": states,
            "emulated": [t for t, s in run.sessions.items() if not s.get("real")]}
