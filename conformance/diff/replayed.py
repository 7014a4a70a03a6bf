"""What `gve-conformance replay` prints: what it compared — the target, the reference,
the disagreement the transcript recorded, each frame with the target's answer, the
reference's and the recorded one and how the two were judged — and one verdict line that
follows from it, with the exit status that goes with it (0: PASS; 1: FAIL, NON-STRICT,
INFO or COULD-NOT-TEST)."""

from __future__ import annotations

from dataclasses import dataclass

from conformance.diff.compare import TIMING, delays
from conformance.diff.engine import Disagreement, ExampleRun, StepRecord
from conformance.diff.steps import FILL, FRAME, INPUT, RIG, Step
from conformance.link.framing import readable
from conformance.verdicts.verdict import COULD_NOT_TEST, PASS

#: the sides agree on every answer: what the last line says, and the exit status
AGREE = "the target answers as the reference does"


@dataclass(frozen=True)
class Verdict:
    word: str            # PASS, FAIL, NON-STRICT, INFO, COULD-NOT-TEST
    line: str            # the last line printed
    status: int          # the exit status

    @classmethod
    def could_not_test(cls, why: str) -> Verdict:
        return cls(COULD_NOT_TEST, f"{COULD_NOT_TEST}: {why}", 1)


def recorded_rule(meta: dict[str, str]) -> str:
    """The rule of the disagreement the transcript recorded ("" when it names none)."""
    return meta.get("rules", "").split()[0] if meta.get("rules", "").split() else ""


def header(file: str, target: str, reference: str, profile: str,
           meta: dict[str, str]) -> list[str]:
    """What is compared with what, and what the transcript recorded."""
    out = [f"replay {file}: target {target} against reference {reference} ({profile})"]
    rule = recorded_rule(meta)
    if rule or "target-answer" in meta:
        out.append(f"recorded: {meta.get('verdict', '?')} {rule or '(no known rule)'}: "
                   f"target {meta.get('target-answer', '?')}, reference "
                   f"{meta.get('reference-answer', '?')}"
                   + (f" (on {meta['target']})" if meta.get("target") else ""))
    out.append("each frame: the target's answer now, the reference's now, the one the "
               "transcript expects (recorded), and how the two now were judged")
    return out


def _frames(n: int) -> str:
    return f"{n} frame" if n == 1 else f"{n} frames"


def _one(data: bytes) -> str:
    return readable(data) or "-"


def frame_lines(outcome: ExampleRun, steps: list[Step], expected: list[bytes]) -> list[str]:
    """Each step of the transcript as it went: a frame with both answers now, the one the
    transcript expects (``expected``, step by step) and how the two were judged —
    ``same``, ``alike`` and why (the timing band), or ``DIFFERENT``; a step not sent and
    why; a fill's first and last frames (those between agreed)."""
    by_place: dict[int, list[tuple[int, StepRecord]]] = {}
    for i, rec in enumerate(outcome.records):
        by_place.setdefault(rec.place, []).append((i, rec))
    refused = iter(outcome.refused)
    d = outcome.disagreement
    reached = outcome.records[-1].place if outcome.records else -1
    out: list[str] = []
    for place, step in enumerate(steps):
        if place > reached and (d is not None or outcome.ended):
            why = "a replay stops at its first disagreement" if d is not None \
                else "the replay ended early"
            out.append(f"  ... {len(steps) - place} step(s) not sent: {why}")
            break
        recs = by_place.get(place, [])
        if not recs and step.kind in (INPUT, RIG):
            out.append(f"  = {step}: not replayed (a side has no rig, or its rig stopped "
                       "answering)")
            continue
        if not recs and step.kind in (FRAME, FILL):
            out.append(f"  not sent (the guard): {next(refused, step)}")
            continue
        if step.kind == FILL:
            out.append(f"  = {step}: {len(recs)} frame(s) sent")
        shown = recs if len(recs) <= 2 else [recs[0], recs[-1]]
        for i, rec in shown:
            if rec.step.kind not in (FRAME, FILL) or rec.target is None:
                out.append(f"  = {rec.step}")
                continue
            if len(recs) > 2 and (i, rec) == recs[-1]:
                out.append(f"  ... {len(recs) - 2} more frames of the fill, each answered "
                           "alike")
            judged = (_different(d) if d is not None and i == d.index
                      else f"alike: {rec.alike}" if rec.alike else "same")
            was = expected[place] if rec.repeat == 0 and place < len(expected) else b""
            out.append(f"  > {readable(rec.target.sent):28} target "
                       f"{_one(rec.target.answer):16} reference {_one(rec.reference.answer):16}"
                       f" recorded {_one(was):16} {judged}")
    out += [f"  not sent (the guard): {note}" for note in refused]
    return out


def _different(d: Disagreement) -> str:
    """``DIFFERENT (code)``; a timing difference with both sides' instants."""
    if d.kind != TIMING:
        return f"DIFFERENT ({d.kind})"
    target, reference = delays(d.target, d.reference)
    return f"DIFFERENT (timing: the target answered {target} after the frame, the " \
        f"reference {reference})"


def _not_run(steps: list[Step], outcome: ExampleRun) -> list[Step]:
    """The rig's input steps left out (a side without a rig, or one that stopped
    answering)."""
    done = {rec.place for rec in outcome.records if rec.step.kind in (INPUT, RIG)}
    return [s for i, s in enumerate(steps) if s.kind in (INPUT, RIG) and i not in done]


def verdict(outcome: ExampleRun, steps: list[Step], meta: dict[str, str]) -> Verdict:
    """The one verdict the comparison gives: a disagreement (still the recorded one, or
    another); else agreement on every frame, unless something of the transcript was not
    replayed (then it could not be tested)."""
    d = outcome.disagreement
    recorded = recorded_rule(meta)
    if d is not None:
        rule = d.rule or "(no known rule)"
        if recorded and d.rule == recorded:
            still = "still there"
        elif recorded:
            still = f"a disagreement other than the recorded {recorded}"
        else:
            still = "the sides disagree"
        target, reference = (readable(d.target.answer) or "(none)",
                             readable(d.reference.answer) or "(none)")
        if d.kind == TIMING:              # the same bytes: when each came
            after = delays(d.target, d.reference)
            target, reference = f"{target} after {after[0]}", f"{reference} after {after[1]}"
        return Verdict(d.verdict, f"{d.verdict} {rule}: {readable(d.target.sent)} target "
                       f"{target}, reference {reference} ({d.kind}): {still}", 1)
    if outcome.refused:
        return Verdict.could_not_test(
            f"{len(outcome.refused)} step(s) not sent (the guard), so the transcript was "
            f"not replayed whole; the {_frames(outcome.frames)} sent agreed")
    if outcome.ended:
        return Verdict.could_not_test(f"the replay ended early ({outcome.ended}); the "
                                      f"{_frames(outcome.frames)} before agreed")
    skipped = _not_run(steps, outcome)
    if skipped:
        return Verdict.could_not_test(
            f"{len(skipped)} input step(s) not replayed (a side has no rig, or its rig "
            f"stopped answering); the {_frames(outcome.frames)} sent agreed")
    gone = f"; the recorded {recorded} disagreement is gone" if recorded else ""
    return Verdict(PASS, f"{PASS}: {AGREE} ({_frames(outcome.frames)}){gone}", 0)
