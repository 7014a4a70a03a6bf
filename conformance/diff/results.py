"""Findings as the suite's results, so the usual reports (JUnit, JSON, HTML) show them:
one result per disagreement, filed under its rule's section, with both answers side by
side (observed: the target's, expected: the reference's) and its transcript; one
result for the whole search when the sides agreed throughout."""

from __future__ import annotations

import re

from conformance.diff.compare import TIMING, delays
from conformance.diff.engine import Finding
from conformance.link.framing import readable
from conformance.run.runner import CaseResult
from conformance.verdicts.check import Check
from conformance.verdicts.quoting import answer_text, quoted
from conformance.verdicts.verdict import COULD_NOT_TEST, PASS
from gve_fixtures.rules import load_rules


def _slug(text: str) -> str:
    return re.sub(r"[^a-z0-9]+", "-", text.lower()).strip("-") or "frame"


def finding_result(f: Finding, *, profile: str, target: str, transcript: list[str],
                   path: str = "") -> CaseResult:
    d = f.disagreement
    rule = load_rules().get(d.rule) if d.rule else None
    section = rule.section if rule else "diff"
    slug = _slug({"*E": "packet-end", "*S": "packet-start", "@": "index", ">": "repeat",
                  "?": "version", "%": "checksum-mode", "$": "short"}.get(d.command, d.command))
    r = CaseResult(f"{section}.diff.{slug}-{d.kind}", section,
                   rule.text if rule else "the target answers as the reference does",
                   d.tag, rule.source if rule else "gve-conformance diff", profile, target,
                   d.verdict)
    sent = readable(d.target.sent)
    if d.kind == TIMING:      # the same bytes: what differs is when they came
        observed, expected = delays(d.target, d.reference)
        answer = quoted(answer_text(d.target.answer))
        check = Check(False, f"{sent} answered {answer} at another instant ({d.kind})",
                      f"{observed} after the frame", f"{expected} after the frame", d.tag,
                      d.rule or "")
    else:
        check = Check(False, f"{sent} answered differently ({d.kind})",
                      answer_text(d.target.answer), answer_text(d.reference.answer), d.tag,
                      d.rule or "")
    r.checks = [check.to_dict()]
    r.notes = [f"rule touched: {d.rule or 'none known'}",
               f"shrunk to {f.frames} frame(s): " + " | ".join(str(s) for s in f.steps)]
    if f.unreplayed:
        r.notes.append(f.unreplayed)
    if f.outcome.refused:
        r.notes.append("not sent (the guard): " + "; ".join(f.outcome.refused))
    r.wire_log = transcript
    r.frames = f.frames
    if path:
        r.artifacts = {"transcript": path}
    return r


def agreement_result(*, profile: str, target: str, examples: int, frames: int,
                     seconds: float) -> CaseResult:
    r = CaseResult("diff.search.agreement", "diff", "the target answers as the reference "
                   "does", "M", "gve-conformance diff", profile, target, PASS)
    r.checks = [Check(True, f"{examples} sequences, {frames} frames: every answer alike",
                      tag="M").to_dict()]
    r.frames, r.seconds = frames, seconds
    if not examples:
        # a search that ran no sequence (its time up before the first) has shown nothing
        r.verdict, r.checks = COULD_NOT_TEST, []
        r.notes = [f"no sequence ran in {seconds:.1f} s: nothing was compared"]
    return r


def rig_lost_result(*, profile: str, target: str, why: str) -> CaseResult:
    """The rig's input steps, left out once the target's rig stopped answering."""
    r = CaseResult("diff.search.rig-inputs", "diff", "inputs set by the rig are answered "
                   "as the reference answers them", "M", "gve-conformance diff", profile,
                   target, COULD_NOT_TEST)
    r.notes = [f"input steps not tested: {why}"]
    return r
