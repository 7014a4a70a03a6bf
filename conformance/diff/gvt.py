"""A finding as a transcript (``fixtures/README.md``): the frames exactly as sent, the
reference's answers as the expected `<` records, the target's answer beside each one as a
comment, waits, rig inputs and filled queues as actions; and back into steps for
`gve-conformance replay`.
"""

from __future__ import annotations

import math
from pathlib import Path

from conformance.diff.engine import Finding, StepRecord
from conformance.diff.steps import FILL, FRAME, INPUT, RIG, STATE, WAIT, Step
from conformance.link.framing import HostFramer, readable
from conformance.reports.files import write_text
from gve_fixtures.transcript import (
    ACTION,
    HOST,
    UNIT,
    Record,
    Transcript,
    TranscriptError,
    unescape,
)


def transcript(finding: Finding, *, profile: str, target: str, reference: str,
               seed: int | None = None) -> Transcript:
    d = finding.disagreement
    meta = {
        "title": f"diff: {d.command or '?'} answered differently ({d.kind})",
        "source": "gve-conformance diff",
        "rules": d.rule or "",
        "tag": d.tag,
        "profiles": profile,
        "target": target,
        "reference": reference,
        "verdict": d.verdict,
        "target-answer": readable(d.target.answer) or "(none)",
        "reference-answer": readable(d.reference.answer) or "(none)",
    }
    if seed is not None:
        meta["seed"] = str(seed)
    if not d.rule:
        del meta["rules"]
    lines: list[Record] = []
    records = finding.outcome.records
    for i, rec in enumerate(records):
        last = i == len(records) - 1
        if rec.step.kind == FILL and not last and _fill_ends(records, i):
            first = records[i - rec.repeat]
            lines.append(Record(ACTION, f"fill {rec.repeat + 1} {_payload(first)}".encode(),
                              first.target.sent_at))
            continue
        if rec.step.kind == FILL and not last:
            continue
        lines += _lines(rec, last and d is not None, d.rule if last else None, d.verdict)
    return Transcript(meta, lines)


def _payload(rec: StepRecord) -> str:
    return Record(HOST, rec.target.sent).line().split(" ", 1)[1]


def _fill_ends(records: list[StepRecord], i: int) -> bool:
    """Whether record ``i`` ends the part of its fill written as one action: the next
    record is another step, or the last one (the disagreement, written as a frame)."""
    nxt = records[i + 1]
    return nxt.step is not records[i].step or nxt.repeat == 0 or i + 2 == len(records)


def _lines(rec: StepRecord, disagreeing: bool, rule: str | None, verdict: str) -> list[Record]:
    step = rec.step
    if step.kind == WAIT:
        return [Record(ACTION, f"wait {step.seconds:g}".encode())]
    if step.kind == INPUT:
        return [Record(ACTION, f"input {step.port} {step.value:02X}".encode())]
    if step.kind == RIG:
        return [Record(ACTION, step.body.encode())]
    if step.kind == STATE:
        note = ""
        if rec.target is not None and rec.reference is not None:
            what = rec.target.sent.decode("ascii", "replace").partition(":")[2]
            note = (f"{what}: reference {readable(rec.reference.answer)}, target "
                    f"{readable(rec.target.answer)}")
            if disagreeing:
                note = f"[{verdict} {rule or 'no known rule'}] {note}"
        return [Record(ACTION, b"state", comment=note)]
    out: list[Record] = []
    sent = rec.target.sent
    if step.stall is not None:
        at, seconds = step.stall
        out += [Record(HOST, sent[:at], rec.target.sent_at),
                Record(ACTION, f"wait {seconds:g}".encode(), comment="stalled: the watchdog"),
                Record(HOST, sent[at:])]
    else:
        out.append(Record(HOST, sent, rec.target.sent_at))
    expected = rec.reference.answer
    differs = rec.target.answer != expected
    note = f"target: {readable(rec.target.answer) or '(none)'}" if differs else ""
    if disagreeing:
        note = f"[{verdict} {rule or 'no known rule'}] {note}".strip()
    pieces = [p + b"\r" for p in expected.split(b"\r")[:-1]] if expected else []
    if expected and not expected.endswith(b"\r"):
        pieces.append(expected.rsplit(b"\r", 1)[-1])
    for j, piece in enumerate(pieces):
        out.append(Record(UNIT, piece, rec.reference.received_at if j == 0 else None,
                        note if j == len(pieces) - 1 else ""))
    if not pieces and note:
        out.append(Record(ACTION, b"silence 0", comment=f"reference: (none); {note}"))
    return out


def write(path: str | Path, t: Transcript) -> Path:
    return write_text(path, t.dumps(), encoding="ascii")


def steps_of(t: Transcript) -> list[Step]:
    """The steps a transcript replays: each frame's bytes exactly, an answer due when
    `<` records follow it (as many lines as there are), waits, inputs, fills."""
    return [step for step, _ in _parsed(t)]


def expected_of(t: Transcript) -> list[bytes]:
    """Step by step (as :func:`steps_of`), the answer the transcript expects: its `<`
    records after the frame, joined (empty for an action, a fill included)."""
    return [answer for _, answer in _parsed(t)]


def _parsed(t: Transcript) -> list[tuple[Step, bytes]]:
    steps: list[tuple[Step, bytes]] = []
    records = t.records
    i = 0
    while i < len(records):
        r = records[i]
        if r.direction == HOST:
            data, stall = r.data, None
            j = i + 1
            # a frame in pieces with a wait between: a stalled frame
            if (j + 1 < len(records) and records[j].direction == ACTION
                    and records[j].action[0] == "wait" and records[j + 1].direction == HOST
                    and not data.endswith(b"\r")):
                stall = (len(data), _wait(records[j].action).seconds)
                data += records[j + 1].data
                j += 2
            answer = []
            while j < len(records) and records[j].direction == UNIT:
                answer.append(records[j].data)
                j += 1
            steps.append((Step(FRAME, _body(data), answer=bool(answer),
                               lines=max(len(answer), 1), stall=stall, raw=data),
                          b"".join(answer)))
            i = j
            continue
        if r.direction == ACTION and r.action[0] in _ACTIONS:
            steps.append((_action(r.action), b""))
        i += 1
    return steps


#: the longest `= wait` replayed, and the most frames one `= fill` sends
LONGEST_WAIT = 3600.0
LARGEST_FILL = 100_000


def _wait(words: list[str]) -> Step:
    seconds = float(words[1])
    if not math.isfinite(seconds) or not 0 <= seconds <= LONGEST_WAIT:
        raise ValueError(f"give 0 to {LONGEST_WAIT:g} seconds")
    return Step(WAIT, seconds=seconds)


def _input(words: list[str]) -> Step:
    port, value = int(words[1]), int(words[2], 16)
    if not (0 <= port <= 99 and 0 <= value <= 0xFF):
        raise ValueError("give a port number and a byte in hex (00..FF)")
    return Step(INPUT, port=port, value=value)


def _fill(words: list[str]) -> Step:
    times, data = int(words[1]), unescape(words[2])
    if not 1 <= times <= LARGEST_FILL:
        raise ValueError(f"give 1 to {LARGEST_FILL} frames")
    return Step(FILL, _body(data), times=times, raw=data)


def _power_on(words: list[str]) -> Step:
    if len(words) != 1:
        raise ValueError("give power-on alone")
    return Step(RIG, "power-on")


def _switch(words: list[str]) -> Step:
    axis, where = words[1:] if len(words) == 3 else ("", "")
    if axis not in ("X", "Y", "Z", "A") or not (
            where == "none" or (where.lstrip("-").isdigit() and len(where) <= 12)):
        raise ValueError("give an axis (X, Y, Z, A) and a position or none")
    return Step(RIG, f"switch {axis} {where}")


#: the actions a replay performs (the others, e.g. a log's `= fault`, are notes)
_ACTIONS = {"wait": _wait, "input": _input, "fill": _fill,
            "state": lambda words: Step(STATE), "power-on": _power_on, "switch": _switch}


def _action(words: list[str]) -> Step:
    try:
        return _ACTIONS[words[0]](words)
    except (ValueError, IndexError) as err:
        why = str(err) if isinstance(err, ValueError) and "give" in str(err) else "malformed"
        raise TranscriptError(f"= {' '.join(words)}: {why}") from None


def _body(data: bytes) -> str:
    frames = HostFramer().frames(data)
    return frames[-1].bodies(None)[-1] if frames else ""
