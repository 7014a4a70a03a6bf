"""The host rules, judged on the wire after each run: one function per
kind of evidence, each naming the rules of fixtures/rules.toml it judges.

:data:`WIRE_CHECKS` maps every rule a host can fail here to the check that judges it
(``oracle.HOST_CHECKS`` adds the rules the executed motion judges). Verdicts come from
the rules' tags, as for units; a finding may carry its own tag where the spec's preamble
says so (a hang is a FAIL whatever the tag).
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field

from conformance.host.examples import worked_frames
from conformance.host.frame_rules import UNSUMMED
from conformance.host.recording import STALL_NS, Exchange, Recording, Unsolicited, show
from conformance.host.unitview import VECTORS, UnitView
from conformance.protocol.catalogue import classes
from gve_fixtures.profile import Profile
from gve_fixtures.protocol import ErrorCode

#: the least a host waits for an answer before it may treat it as lost (spec 8 [D])
PATIENCE_MS = 100
MS = 1_000_000
#: `@` and `>`: asking, never resending (spec 8)
ASKING = classes(asks=True)
#: what a host may send again instead of asking: once or twice, the unit is left alike
REPEATABLE = classes(repeatable=True)
#: what only reads: sent while a host waits to ask, it trusts nothing
QUERIES = classes(query=True)
#: the reads that tell what became of a frame: the index (`@`, `>`) and the positions
TELLING = QUERIES & (ASKING | classes(position=True))


@dataclass(frozen=True)
class Finding:
    """A rule broken at instant ``t`` (ns since the run began), with the frame shown."""

    rule: str
    t: int
    frame: str
    what: str
    tag: str | None = None          # overrides the rule's tag


@dataclass
class LineFacts:
    """What the checks need to know about the line and the run."""

    views: list[UnitView]
    units: dict[int, Profile]       # address -> profile
    baud: int
    origin: int
    exit_code: int | None = None

    @property
    def watchdog_ms(self) -> int:
        return min(p.watchdog_ms for p in self.units.values())


@dataclass
class Judgement:
    findings: list[Finding] = field(default_factory=list)
    judged: set[str] = field(default_factory=set)
    notes: list[str] = field(default_factory=list)

    def add(self, rule: str, t: int, frame: str, what: str, tag: str | None = None) -> None:
        self.findings.append(Finding(rule, t, frame, what, tag))


Check = Callable[[Recording, LineFacts, Judgement], None]


def _at(t: int, line: LineFacts) -> int:
    return t - line.origin


#: the refusals a host may provoke on purpose: unknown, syntax, range (spec 5)
REFUSALS = {ErrorCode.UNKNOWN: "5.code.unknown", ErrorCode.SYNTAX: "5.code.syntax",
            ErrorCode.RANGE: "5.code.range"}
#: why a probe is graded by our reading, not by the unit's rule
PROBE = ("refused once and never sent again: a probe the host made and took the "
         "refusal of (that a host sends only what the unit accepts is our reading, "
         "spec 5 [D])")


def probes(rec: Recording) -> set[int]:
    """The exchanges (by ``n``) a host sent to learn how the unit answers: refused as
    unknown, for syntax or for range with no fault of ours, their command refused nowhere
    else in the run, the frame never sent again, and the host going on after it. No
    sentence of the manuals forbids a host to send a frame the unit refuses; a host that
    leans on refused frames repeats them, has more than one of a command refused, or
    stops at the refusal."""
    refused = [ex for ex in rec.exchanges
               if ex.fault is None and ex.code in REFUSALS and not _lapsed(ex)]
    commands = Counter(ex.parsed.command or ex.parsed.key for ex in refused)
    sent = Counter(ex.frame.raw for ex in rec.exchanges)
    last = rec.exchanges[-1].n if rec.exchanges else -1
    return {ex.n for ex in refused
            if commands[ex.parsed.command or ex.parsed.key] == 1 and sent[ex.frame.raw] == 1
            and ex.n < last}


def frames(rec: Recording, line: LineFacts, out: Judgement) -> None:
    """Each frame on its own: grammar, address, command, parameters, checksum, length
    (frame_rules.py), and a member of a packet carrying its own checksum (spec 7). What a
    probe (:func:`probes`) breaks is graded by our reading: the unit refused it."""
    probing = probes(rec)
    for ex in rec.exchanges:
        out.judged |= ex.parsed.judged
        probe = ex.n in probing
        for p in ex.parsed.problems:
            out.add(p.rule, _at(ex.frame.start, line), ex.text,
                    f"{p.what}: {PROBE}" if probe else p.what, "D" if probe else None)
    for frag in rec.fragments:
        out.judged.add("3.frame.grammar")
        shown = show(frag.data)
        if frag.kind == "cut":
            out.add("3.frame.grammar", _at(frag.start, line), shown,
                    "a frame that never ended with CR")
        elif frag.kind == "stray":
            out.add("3.frame.grammar", _at(frag.start, line), shown,
                    "bytes outside any frame (units ignore them, spec 3 [D])", "D")
        else:
            out.add("3.frame.grammar", _at(frag.start, line), shown,
                    "a LF after CR (units ignore it, spec 3 [D])", "D-info")


def refusals(rec: Recording, line: LineFacts, out: Judgement) -> None:
    """A frame the unit refused as unknown, for syntax or for range is the host's fault
    (spec 5), unless a fault of ours made it so; so is one refused as "not while moving"
    (7): the host did not wait for the motion to end, as `L0,0,0` lets it (spec 10.1).
    A frame summed after a restart turned checksum mode off is refused for that cause,
    which its reading names (6.checksum.off-after-reset), not for its parameters. A `*E`
    refused after a packet was opened closes one the host could not know closed (spec 7:
    only `*E` is sure to), as its answer or a fault left it unsure: no fault of the host's.
    A probe (:func:`probes`) is graded by our reading."""
    rules = {**REFUSALS, ErrorCode.BUSY: "10.1.queue.wait-idiom"}
    out.judged |= set(rules.values())
    probing = probes(rec)
    opened = False
    for ex in rec.exchanges:
        closer = opened and ex.parsed.command == "*E"
        opened = opened or ex.parsed.command == "*S"
        if ex.fault is None and ex.code in rules and not _lapsed(ex) and not closer:
            answer = b"".join(ex.answer).decode("latin-1").strip()
            probe = ex.n in probing
            out.add(rules[ErrorCode(ex.code)], _at(ex.frame.start, line), ex.text,
                    f"the unit answered {answer}" + (f"; {PROBE}" if probe else ""),
                    "D" if probe else None)


def _lapsed(ex: Exchange) -> bool:
    """Whether the refusal is the checksum mode's, which a reading names: a frame summed
    after a restart turned the mode off, or a read sent unsummed in it."""
    return any(p.rule in ("6.checksum.off-after-reset", UNSUMMED)
               for p in ex.parsed.problems)


def gaps(rec: Recording, line: LineFacts, out: Judgement) -> None:
    """The pauses between a frame's bytes stay below the unit's watchdog (spec 3): the
    slowest one is measured and shown; a pause while the relay itself was late is not
    held against the host."""
    out.judged.add("3.frame.watchdog")
    limit = line.watchdog_ms * MS
    slowest = max((ex.frame.slowest_gap for ex in rec.exchanges), default=0)
    out.notes.append(f"slowest gap between the bytes of a frame: {slowest / MS:.1f} ms "
                     f"(watchdog {line.watchdog_ms} ms)")
    for ex in rec.exchanges:
        long = [(a, b) for a, b in ex.frame.pauses if b - a >= limit]
        ours = [(a, b) for a, b in long if any(s < b and e > a for s, e in rec.stalls)]
        if ours:
            out.notes.append(f"{len(ours)} long gap(s) in {ex.text} not judged: the relay "
                             "was late itself")
        theirs = [p for p in long if p not in ours]
        if theirs:
            a, b = max(theirs, key=lambda p: p[1] - p[0])
            out.add("3.frame.watchdog", _at(a, line), ex.text,
                    f"{(b - a) / MS:.1f} ms between two bytes (watchdog "
                    f"{line.watchdog_ms} ms)")


def simplex(rec: Recording, line: LineFacts, out: Judgement) -> None:
    """No frame before the previous one is answered (spec 2), unless the host waited at
    least PATIENCE_MS and gave the answer up for lost."""
    out.judged.add("2.link.simplex")
    previous: Exchange | None = None
    unsure = 0
    for ex in rec.exchanges:
        if previous is not None:
            delivered = previous.delivered_at
            waited = ex.frame.start - previous.frame.end
            if ((delivered is None or delivered > ex.frame.start)
                    and waited < PATIENCE_MS * MS):
                if _relay_late(previous.frame.end, rec):
                    unsure += 1
                else:
                    out.add("2.link.simplex", _at(ex.frame.start, line), ex.text,
                            f"sent {waited / MS:.2f} ms after {previous.text}, before its "
                            "answer")
        if ex.answer:
            previous = ex
    if unsure:
        out.notes.append(f"{unsure} frame(s) not judged for 2.link.simplex: the relay was "
                         "late itself and read them with the frame before")


def _relay_late(t: int, rec: Recording) -> bool:
    """Whether bytes stamped at ``t`` may have come long before: the relay did not read
    the host's port for a while just before (``t`` at or just after a stall)."""
    return any(start - STALL_NS <= t <= end + STALL_NS for start, end in rec.stalls)


def packets(rec: Recording, line: LineFacts, out: Judgement) -> None:
    """`*E n` gives the members sent since `*S`, and only `C` and `B` are members
    (spec 7). A `*E` with no packet open right after one whose answer the host did not
    get intact, or that was no `0,n`, closes a packet the host could not know closed
    (only `*E` is sure to): no fault of the host's."""
    members: dict[int, int | None] = {}
    unsure: set[int] = set()        # addresses whose last packet may still be open
    for ex in rec.exchanges:
        f = ex.parsed
        if f.address is None or f.command is None:
            continue
        n = members.get(f.address)
        if f.command == "*S":
            out.judged |= {"7.packet.count", "7.packet.members", "7.packet.exchange"}
            members[f.address] = 0
        elif f.command == "*E":
            out.judged.add("7.packet.exchange")
            if n is None and f.address not in unsure:
                out.add("7.packet.exchange", _at(ex.frame.start, line), ex.text,
                        "`*E` with no packet open")
            elif n is not None and f.params[:1] != [str(n)]:
                out.add("7.packet.count", _at(ex.frame.start, line), ex.text,
                        f"{n} member(s) sent since `*S`")
            if n is not None and (ex.fault is not None or not ex.intact or ex.code != ErrorCode.OK):
                unsure.add(f.address)
            else:
                unsure.discard(f.address)
            members[f.address] = None
        elif n is not None:
            if f.command in classes(packet="breaker"):
                members[f.address] = None          # breaks the packet (spec 7)
                continue
            members[f.address] = n + 1             # a member, failing or not
            if f.command not in classes(packet="member"):
                out.add("7.packet.members", _at(ex.frame.start, line), ex.text,
                        f"`{f.command}` inside a packet")
            elif f.checksum is None and summed(ex):
                out.judged.add("7.packet.checksums")
                out.add("7.packet.checksums", _at(ex.frame.start, line), ex.text,
                        "a member without its checksum in checksum mode")
            elif summed(ex):
                out.judged.add("7.packet.checksums")


def summed(ex: Exchange) -> bool:
    """Whether the unit was in checksum mode for this frame (spec 6)."""
    return "6.checksum.sum" in ex.parsed.judged


def restarts(rec: Recording, line: LineFacts, out: Judgement) -> None:
    """After `J` the host sends nothing until the unit is ready again (spec 2)."""
    for ex in rec.exchanges:
        if ex.parsed.command != "J" or ex.code != ErrorCode.OK or ex.delivered_at is None:
            continue
        out.judged.add("2.link.ready-after-restart")
        profile = line.units[ex.parsed.address or 0]
        ready = ex.delivered_at + profile.restart_ms * MS
        early = [e for e in rec.exchanges if ex.delivered_at < e.frame.start < ready]
        if early:
            e = early[0]
            out.add("2.link.ready-after-restart", _at(e.frame.start, line), e.text,
                    f"sent {(e.frame.start - ex.delivered_at) / MS:.0f} ms after `J` was "
                    f"answered (the unit restarts for {profile.restart_ms} ms)")


def recovery(rec: Recording, line: LineFacts, out: Judgement) -> None:
    """After an answer the host did not get whole, it asks `@` (and `>`) before anything
    else and never resends a vector blindly (spec 8); in checksum mode an answer whose
    checksum fails is not trusted (spec 6). Sending a repeatable command again at once
    (a setting or a read: M84 12.5.12 "Většina příkazů se dá zopakovat") trusts nothing
    and leaves the unit as one run would: a recovery the manual names, no finding. Pure
    reads (the catalogue's queries) trust nothing; a host that read the index or the
    positions before it acted found out what became of the frame, and did not trust the
    damaged answer (what it made of the reads, the executed motion judges)."""
    for i, ex in enumerate(rec.exchanges):
        if ex.fault is None or ex.fault in ("cut-frame", "queue-full", "interrupt",
                                            "restart"):
            continue
        # a `*E0` first closes a packet that may be open and commits no member (a count
        # no packet that had members gives): what the host does next is judged
        rest = [e for e in rec.exchanges[i + 1:] if not _closer(e)]
        if not rest:
            continue
        nxt = rest[0]
        told = False
        if not _resends(ex, nxt):
            # reads first (F until the motion ends, then `@` or PF) trust nothing and
            # change nothing: what the host does after them is what it made of the answer
            # and of what they told it
            acts = next((k for k, e in enumerate(rest)
                         if not _reads(e) or e.parsed.command in ASKING), None)
            if acts is None:
                continue                    # it only read: it trusted nothing
            told = any(e.parsed.command in TELLING for e in rest[:acts])
            nxt = rest[acts]
        asked = nxt.parsed.command in ASKING
        shown = f"after {ex.text} ({ex.fault})"
        out.judged |= {"8.recovery.no-blind-resend", "8.recovery.ask-index"}
        repeated = _resends(ex, nxt) and ex.parsed.command in REPEATABLE
        if ex.fault == "corrupt-answer" and summed(ex):
            out.judged.add("6.checksum.response-sum")
            # a host that read the index or the positions first found out what became
            # of the frame: what it then does rests on them (the motion judges it)
            if not asked and not repeated and not told:
                out.add("6.checksum.response-sum", _at(nxt.frame.start, line), nxt.text,
                        f"trusted an answer whose checksum fails {shown}")
                continue
        if _got_answer(ex, nxt) or repeated:
            continue
        if _resends(ex, nxt):
            motion = ex.parsed.command in (*VECTORS, "*E")
            rule = "8.recovery.no-blind-resend" if motion else "8.recovery.ask-index"
            out.add(rule, _at(nxt.frame.start, line), nxt.text,
                    f"resent {shown} without asking `@` first")
        elif not asked:
            out.add("8.recovery.ask-index", _at(nxt.frame.start, line), nxt.text,
                    f"went on {shown} as if the answer had come")


def _reads(ex: Exchange) -> bool:
    """Whether the frame only reads (spec 10: a status, a port, a position, the index)."""
    return ex.parsed.command in QUERIES


def _got_answer(ex: Exchange, nxt: Exchange) -> bool:
    """Whether the host had the unit's answer, whole, before its next frame (noise
    before an answer leaves the answer whole)."""
    whole = ex.fault in ("late-answer", "noise") and ex.delivered is not None
    return whole and ex.delivered_at is not None and ex.delivered_at <= nxt.frame.start


def _closer(ex: Exchange) -> bool:
    return ex.parsed.command == "*E" and ex.parsed.params[:1] == ["0"]


def _resends(ex: Exchange, nxt: Exchange) -> bool:
    if ex.parsed.command == "*E":
        return nxt.parsed.command in classes(packet="opens") | classes(packet="closes")
    return nxt.frame.raw == ex.frame.raw


def queue_full(rec: Recording, line: LineFacts, out: Judgement) -> None:
    """A vector or packet refused with 1 is sent again later (spec 5, 10.1). Not judged
    when the host had to be stopped (it hung: that is its own finding), nor when it gave
    up (exited non-zero) with no other motion sent after the refusal: it did not go on as
    if the frame had been queued, and its giving up is 8.recovery.finishes's."""
    if line.exit_code is None:
        return
    unsure = gave_up = 0
    for i, ex in enumerate(rec.exchanges):
        if ex.parsed.command not in (*VECTORS, "*E") or ex.delivered is None:
            continue
        told = ex.code == ErrorCode.QUEUE_FULL and ex.fault != "corrupt-answer"
        if not (told or ex.fault == "queue-full"):
            continue
        out.judged.add("5.code.queue-full")
        later = rec.exchanges[i + 1:]
        again = (any(e.parsed.command == "*S" for e in later) if ex.parsed.command == "*E"
                 else any(e.frame.raw == ex.frame.raw for e in later))
        if again:
            continue
        went_on = any(e.parsed.command in (*VECTORS, "*E") for e in later)
        if line.exit_code != 0 and not went_on:
            gave_up += 1
        elif _answer_late_by_relay(ex, rec):
            unsure += 1
        else:
            out.add("5.code.queue-full", _at(ex.frame.start, line), ex.text,
                    "refused with 1 (queue full) and never sent again")
    if unsure:
        out.notes.append(f"{unsure} refusal(s) with 1 not judged for 5.code.queue-full: "
                         "the relay was late itself and gave the answer after the host "
                         "could take it for lost")
    if gave_up:
        out.notes.append(f"the host gave up (exit status {line.exit_code}) while its last "
                         "refused frame waited for room, sending no other motion: not "
                         "judged for 5.code.queue-full")


def _answer_late_by_relay(ex: Exchange, rec: Recording) -> bool:
    """Whether the relay, late itself, gave the host ``ex``'s answer at least
    PATIENCE_MS after the host sent the frame (spec 8 [D]: the host may have given it up
    for lost by then). A stall just before the frame was read counts from its start: the
    frame may have come long before it was stamped."""
    given = ex.delivered_at
    if given is None:
        return False
    return any(start <= given and end + STALL_NS >= ex.frame.end
               and given - min(start, ex.frame.end) >= PATIENCE_MS * MS
               for start, end in rec.stalls)


def port_settings(rec: Recording, line: LineFacts, out: Judgement) -> None:
    """The host sets its port to 8N1 at the line's baud rate (spec 2), as far as the
    port shows it (a pseudo-terminal does; TCP does not)."""
    if not rec.settings:
        return
    out.judged.add("2.link.serial-8n1")
    wanted = f"{line.baud} 8N1"
    for t, seen in rec.settings:
        if seen != wanted:
            out.add("2.link.serial-8n1", _at(t, line), "(port settings)",
                    f"the host set its port to {seen}, the line is {wanted}")
            return


def unsolicited(rec: Recording, line: LineFacts, out: Judgement) -> None:
    """Answers that belong to no complete frame: the unit's watchdog dropped a frame the
    host left unfinished (spec 3)."""
    for u in rec.unsolicited:
        if not _ours(u, rec):
            out.notes.append(f"at {_at(u.t, line) / 1e9:.3f} s the unit answered "
                             f"{b''.join(u.lines)!r} to no complete frame (its watchdog)")


def worked_examples(rec: Recording, line: LineFacts, out: Judgement) -> None:
    """A checksummed frame the spec works out (11 G2: `!0A100,4F`) sent byte for byte as
    the example has it: the host sums its frames as the manuals do."""
    examples = worked_frames()
    out.judged |= {w.rule for w in examples.values()}
    for ex in rec.exchanges:
        raw = ex.frame.raw.rstrip(b"\r")
        body, _, checksum = raw.rpartition(b",")
        w = examples.get(body) if len(checksum) == 2 else None
        unit = line.units.get(ex.parsed.address) if w else None
        if w is None or unit is None or not (not w.families or unit.family in w.families
                                             or unit.name in w.families):
            continue
        if raw != w.frame:
            out.add(w.rule, _at(ex.frame.start, line), ex.text,
                    f"the spec's worked example sends {w.frame.decode('latin-1')}")


def _ours(u: Unsolicited, rec: Recording) -> bool:
    return any(ex.fault == "cut-frame" and ex.frame.end <= u.t for ex in rec.exchanges)


#: the checks run on every recording, in order
CHECKS: tuple[Check, ...] = (frames, refusals, gaps, simplex, packets, restarts, recovery,
                             queue_full, port_settings, unsolicited, worked_examples)

#: every rule a host can fail on the wire -> the check that judges it
WIRE_CHECKS: dict[str, Check] = {
    **{rule: frames for rule in (
        "3.frame.grammar", "3.frame.max-length", "3.frame.upper-case", "2.link.addressed-only",
        "1.profile.command-set", "1.profile.gve54-no-checksums", "1.profile.axes",
        "1.profile.vector-range", "1.profile.v-b-range", "1.profile.v-b-range-gve54",
        "1.profile.dollar-range", "3.params.commas", "3.params.decimal", "3.params.hex-fields",
        "3.params.word-values-decimal", "3.params.float-syntax", "3.params.none-expected",
        "5.code.syntax", "5.code.range", "6.checksum.sum", "6.checksum.off-after-reset",
        UNSUMMED, "10.cmd.vector", "10.cmd.modal",
        "10.cmd.accel-range", "10.cmd.axis-limits", "10.cmd.output", "12.spindle.speed")},
    "5.code.unknown": refusals,
    "10.1.queue.wait-idiom": refusals,
    "3.frame.watchdog": gaps,
    "2.link.simplex": simplex,
    "7.packet.count": packets,
    "7.packet.members": packets,
    "7.packet.exchange": packets,
    "7.packet.checksums": packets,
    "2.link.ready-after-restart": restarts,
    "8.recovery.no-blind-resend": recovery,
    "8.recovery.ask-index": recovery,
    "6.checksum.response-sum": recovery,
    "5.code.queue-full": queue_full,
    "2.link.serial-8n1": port_settings,
    **{w.rule: worked_examples for w in worked_frames().values()},
}


def judge(rec: Recording, line: LineFacts) -> Judgement:
    out = Judgement()
    for check in CHECKS:
        check(rec, line, out)
    seen: set[tuple[str, int, str | None]] = set()
    unique = []
    for f in out.findings:               # a frame's grammar and its refusal: said once
        if (f.rule, f.t, f.tag) not in seen:
            seen.add((f.rule, f.t, f.tag))
            unique.append(f)
    out.findings = unique
    return out


def findings_by_rule(j: Judgement) -> Iterator[tuple[str, list[Finding]]]:
    """Every judged rule with its findings (none: the host kept it), in rule order."""
    by: dict[str, list[Finding]] = {rule: [] for rule in sorted(j.judged)}
    for f in j.findings:
        by.setdefault(f.rule, []).append(f)
    yield from by.items()
