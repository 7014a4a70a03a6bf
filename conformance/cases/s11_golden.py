"""Spec section 11, Golden exchanges from the documents: the cases that check it.

Every golden exchange of spec 11 (fixtures/transcripts/*.gvt) replayed exactly, as a case
``11.golden.<name>``. The player is the suite's own."""

from __future__ import annotations

import math
import re
from pathlib import Path

from conformance.case.context import CaseContext, case
from conformance.cases._kit import configured
from conformance.link.account import Spent
from conformance.link.framing import HostFramer, parse_response
from conformance.link.safety import BeyondEnvelope, Guard
from conformance.protocol.catalogue import classes
from conformance.protocol.parse import parse
from conformance.verdicts.quoting import shown
from gve_fixtures import golden_transcripts
from gve_fixtures.profile import Profile
from gve_fixtures.protocol import TAGS
from gve_fixtures.rules import load_rules
from gve_fixtures.transcript import ACTION, HOST, UNIT, UNIT_MATCH, Transcript, load, unescape

RIG_ACTIONS = {"input", "expect", "power-on"}


def _tag(kind: str | None, default: str) -> str:
    return kind if kind in TAGS else default


def play(ctx: CaseContext, t: Transcript, rule: str | None = None) -> None:
    """Replay ``t``; each expected answer is a check of ``rule`` graded by its record's
    tag."""
    link = ctx.link
    default = _tag(t.tag.kind if t.tag else None, "M-ex")
    for rec in t.records:
        setup = "setup" in rec.comment
        tag = _tag(rec.tag.kind if rec.tag else None, default)
        what = f"{rec.line()}"
        if rec.direction == HOST:
            link.send_raw(rec.data)
        elif rec.direction in (UNIT, UNIT_MATCH):
            lenient = not setup and tag in ("D", "D-info")
            r = link.read_response(30.0, rec.data.count(b"\r") or 1, summed=False,
                                   settle=not lenient)
            got = r.raw if r else b""
            ok = (got == rec.data if rec.direction == UNIT
                  else bool(rec.pattern().fullmatch(got)))
            if not ok and lenient and r is not None:
                # a unit reading this [D] point otherwise may answer with more lines:
                # they are this record's, not a second answer or the next one's
                got += link.rest_of_answer()
            if setup:
                ctx.require(ok, f"setup answered {shown(got)} at {what}")
            else:
                ctx.expect(ok, what, observed=got, expected=rec.data, tag=tag, rule=rule)
        elif rec.direction == ACTION:
            _action(ctx, rec.action, what, tag, rule)


def _action(ctx: CaseContext, words: list[str], what: str, tag: str,
            rule: str | None = None) -> None:
    link, verb, args = ctx.link, words[0], words[1:]
    if verb == "wait":
        link.wait(float(args[0]))
    elif verb == "silence":
        got = link.wait(float(args[0]))
        ctx.expect(got == b"", what, observed=got, expected=b"", tag="always", rule=rule)
    elif verb == "poll":
        frame, pattern = unescape(args[1]), re.compile(unescape(args[2]), re.DOTALL)
        limit = link.now + float(args[0]) * 1e9
        while True:
            link.send_raw(frame)
            r = link.read_response(30.0, summed=False)
            if r is not None and pattern.fullmatch(r.raw):
                break
            ctx.require(link.now < limit, f"{what}: never matched")
            link.wait(0.05)
    elif verb == "fill":
        frame = unescape(args[1])
        for _ in range(int(args[0])):
            link.send_raw(frame)
            r = link.read_response(5.0, summed=False)
            if r is None or r.raw != b"0\r":
                break
    elif verb == "input":
        link.rig.set_input(int(args[0]), int(args[1], 16))
    elif verb == "expect":
        got = ("%02X" % link.rig.outputs()) if args[0] == "outputs" else str(link.rig.spindle())
        ctx.expect(got == args[1], what, observed=got, expected=args[1], tag=tag, rule=rule)
    elif verb == "power-on":
        link.rig.power_on()
        link.wait(2.5, Spent.MANUAL)
    else:
        raise ValueError(f"unknown transcript action {verb!r}")


def envelope_needed(t: Transcript, profile: Profile) -> int | None:
    """The least --max-travel (full steps) with which a real unit's guard lets the whole
    exchange through, or None when none does (a frame it cannot bound): its frames judged
    as the replay's are (a trailing ``,XX`` both ways) and booked with the answers the
    transcript expects (a pattern: unclear, whichever reaches farther)."""
    address = int(t.meta.get("address", profile.address))
    guard = Guard(profile, address, max_travel=2**62, allow_destructive=True)
    framer, summed, pending, need = HostFramer(), False, [], 0.0
    queued = 0           # vectors the exchange has queued (D empties the queue)
    for rec in t.records:
        if rec.direction == HOST:
            pending += framer.frames(rec.data)
            continue
        if rec.direction == ACTION and rec.action[0] in ("fill", "poll"):
            frames = framer.frames(unescape(rec.action[2]))
            if rec.action[0] == "poll":      # until its answer
                batches = [(f, unescape(rec.action[3])) for f in frames]
            else:    # until the queue is full, then 1 (more if vectors end meanwhile)
                sent, room = int(rec.action[1]), max(0, profile.buffer - queued)
                batches = ([(f, b"0\r") for f in frames] * min(sent, room)
                           + [(f, b"1\r") for f in frames] * (sent > room))
        elif rec.direction in (UNIT, UNIT_MATCH):
            # the answer is the last frame's; those before it got none (*S, members)
            answer = rec.data if rec.direction == UNIT else None
            batches = [(f, None) for f in pending[:-1]] + [(f, answer) for f in pending[-1:]]
        else:
            continue
        pending = []
        for f, answer in batches:
            if f.address in guard.addresses:
                need = max(need, *(guard.farthest(body) for body in f.bodies(summed)))
            body = f.bodies(summed)[0]
            r = None if answer is None else parse_response(answer, summed=summed)
            guard.accepted(body, r, f.address)
            if parse(body).name in classes(vector=True) and answer == b"0\r":
                queued += 1
            elif body == "D":
                queued = 0
            if body in ("%+", "%-") and r is not None and r.ok:
                summed = body == "%+"
    return None if math.isinf(need) else math.ceil(need)


def measured_case(path: Path) -> None:
    t = load(path)
    families = t.meta.get("profiles", "").split()
    needs_rig = any(r.direction == ACTION and r.action[0] in RIG_ACTIONS for r in t.records)
    address = int(t.meta.get("address", "-1"))
    needs = t.meta.get("needs", "").split()
    # the golden exchange's own rule (spec "11 G4" -> 11.golden.g4), then those its
    # records check (header "rules:")
    golden = re.search(r"\b11 G(\d+)", t.meta.get("spec", ""))
    rule = f"11.golden.g{golden.group(1)}" if golden else None
    rules = tuple(r for r in (rule, *t.meta.get("rules", "").split()) if r)
    # the exchange's tag where it is not its first rule's (its requirement is the rules')
    tag = _tag(t.tag.kind if t.tag else None, "M-ex")
    own = None if rules and tag == load_rules()[rules[0]].tag else tag

    def applies(profile) -> bool:
        return not families or profile.family in families or profile.name in families

    @case(f"11.golden.{path.stem}", tag=own, rules=rules,
          applies=applies, rig=needs_rig, destructive=bool(t.meta.get("destructive")))
    def replay(ctx: CaseContext) -> None:
        if address >= 0 and address != ctx.link.address:
            ctx.fresh_link(address)
        for name in needs:                   # what the exchange relies on, configured
            configured(ctx, name)
        try:
            play(ctx, t, rule)
        except BeyondEnvelope as stop:
            # data from the manuals, replayed as it is: say what envelope it needs
            need = envelope_needed(t, ctx.profile)
            raise BeyondEnvelope(f"{stop}; " + (
                f"the exchange needs --max-travel {need} or more" if need is not None else
                "no envelope lets the exchange through (a frame the guard cannot bound): "
                "the emulator only")) from None


for _path in golden_transcripts():
    measured_case(_path)
