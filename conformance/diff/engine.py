"""The differential engine: a sequence of steps sent to a target and a reference alike,
answer by answer compared; Hypothesis draws the sequences from the grammar and shrinks
each disagreement to a minimal sequence, which is labelled, graded and kept once.

A sequence stops at its first disagreement: after it the two sides are in different
states and everything later would differ too.
"""

from __future__ import annotations

import contextlib
import math
import random
import re
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field, replace

from hypothesis import HealthCheck, Phase, find, settings
from hypothesis.errors import Flaky, NoSuchExample
from hypothesis.internal.conjecture import providers
from hypothesis.internal.constants_ast import Constants

from conformance.diff.compare import Judge, alike_because, difference
from conformance.diff.grammar import Grammar, Options, load_grammar
from conformance.diff.index import QUERIES, IndexBase
from conformance.diff.labels import allowed, command_of, label, verdict_of
from conformance.diff.sides import Exchange, Side
from conformance.diff.steps import FILL, FRAME, INPUT, WAIT, Step, frames_in
from conformance.link.safety import SafetyStop, TargetNotResponding
from gve_fixtures.profile import Profile
from gve_fixtures.protocol import St6

#: frames that close an open packet (spec 7)
_PACKET_BREAKERS = ("*E", "H", "@", ">", "J")
_LONG_DECIMAL = re.compile(r"\d{13,}")
#: a vector that moves nothing (and so waits no dwell)
_ZERO_VECTOR = re.compile(r"[LC][-+0,]*")
#: real time: how long the reference must have been at rest, besides the target's
#: window, for positions to be compared exactly (a target's motion ends when the unit
#: says, the reference's when its model does)
SETTLE_NS = 50_000_000
#: real time: how long the fresh reference stands before a sequence
AGE_SECONDS = 1.0


@dataclass
class Record:
    """One step as it went: the step, the frame's bytes and both sides' exchanges."""

    step: Step
    target: Exchange | None = None
    reference: Exchange | None = None
    repeat: int = 0                      # FILL: frames of it before this one
    place: int = 0                       # the step's place in its sequence
    #: answers whose bytes differ but were judged alike: why (the timing band, the index
    #: counted from each side's start); "" when the bytes are the same
    alike: str = ""


@dataclass
class Disagreement:
    index: int                           # the record it happened on
    command: str
    kind: str
    target: Exchange
    reference: Exchange
    context: frozenset[str]
    earlier: frozenset[str]
    rule: str | None = None
    verdict: str = ""
    tag: str = ""

    @property
    def signature(self) -> tuple:
        """What makes two disagreements one: the rule and the kind of difference (one
        bug shows on many commands), or the command where no rule is known."""
        return (self.rule, self.kind) if self.rule else (None, self.command, self.kind)


@dataclass
class Outcome:
    records: list[Record] = field(default_factory=list)
    disagreement: Disagreement | None = None
    frames: int = 0
    refused: list[str] = field(default_factory=list)     # steps the guard did not send
    ended: str = ""                                      # why the sequence ended early


class Pair:
    """A target and its reference, run step by step."""

    def __init__(self, target: Side, reference: Side, profile: Profile) -> None:
        self.target = target
        self.reference = reference
        self.profile = profile
        self.exact = target.virtual and reference.virtual
        # the fastest an axis's counter can change: the variant's top rate, in counter
        # units (GVE54: a coarse micro-step mode moves several sixteenths a step)
        self._factor = max(profile.microstep.factors.values()) if profile.microstep else 1
        self.judge = Judge(exact=self.exact, rate=profile.max_rate * self._factor)
        self._ceiling = _Ceiling(profile)
        self._idle_since: int | None = 0
        self._latency_ns = self._slack_ns = self._cut_ns = 0   # real time: see _retimed
        self._lost = False
        self._eeprom_changes: dict[int, int] | None = None   # real target: see _prelude
        self._index = IndexBase()
        #: real time: disagreements seen once that their sequence did not show again
        self.unconfirmed: list[Finding] = []

    # -- one example ----------------------------------------------------------------------
    def run(self, steps: list[Step]) -> Outcome:
        out = Outcome()
        try:
            self.target.open()
        except SafetyStop as err:
            # the known state itself was refused (a minimiser's candidate left the unit
            # where the guard cannot bring it back): the candidate shows nothing
            out.refused.append(f"the known state: {err}")
            return out
        self.reference.open()
        self._idle_since = 0
        self._latency_ns = self._slack_ns = self._cut_ns = 0
        self._lost = False
        self._index = IndexBase()
        if self.target.real:
            self._prelude()
        context_packet = False
        earlier: set[str] = set()
        dwell = _Dwell(self.profile.reset.T)
        self._ceiling = _Ceiling(self.profile)
        queued: str | None = None
        for place, step in enumerate(steps):
            if step.kind == WAIT:
                self.target.wait(step.seconds)
                if not self.exact:
                    # looked at before the wait's end too: a motion that ended early in a
                    # long wait is at rest for a read right after it
                    self._follow(self.target.now - 2 * SETTLE_NS)
                    self._watch_reference()
                self._follow(self.target.now)
                out.records.append(Record(step, place=place))
                continue
            if step.kind == INPUT:
                if self.target.has_rig and self.reference.has_rig:
                    self._retimed("input", None)
                    if (self.target.set_input(step.port, step.value)
                            and self.reference.set_input(step.port, step.value)):
                        out.records.append(Record(step, place=place))
                        earlier.add("input")
                continue
            command = command_of(step.body)
            times = step.times if step.kind == FILL else 1
            for i in range(times):
                rec = self._exchange(step, out)
                if rec is None:
                    break
                rec.repeat, rec.place = i, place
                out.records.append(rec)
                self._retimed(command, rec)
                if command in QUERIES:
                    self._base_index(command, self._context(step, context_packet), rec)
                kind = self._difference(command, rec)
                if kind is not None:
                    context = self._context(step, context_packet)
                    if command == "@" and self._index.counts_queries(
                            _values(rec.target), _values(rec.reference)):
                        context.add("queries-counted")
                    facts = (command, kind, context, earlier, _code(rec.reference),
                             _code(rec.target))
                    if (why := allowed(*facts)) is not None:
                        out.ended = f"both answers allowed: {why}"
                        return self._end(out)
                    if dwell.within(rec.reference.sent_at):
                        context.add("in-dwell")
                    d = Disagreement(len(out.records) - 1, command, kind, rec.target,
                                     rec.reference, frozenset(context), frozenset(earlier))
                    d.rule = label(*facts)
                    d.verdict, d.tag = verdict_of(d.rule, self.target.target.info.strict)
                    out.disagreement = d
                    return self._end(out)
                if i == 0:             # a fill's later vectors join the first: no dwell
                    dwell.note(command, step.body, rec.reference)
                queued = _queued(command, step.body, rec.reference, queued)
                self._ceiling.note(command, step.body, rec.reference)
                if queued == "C+C":
                    earlier.add("junction")
                if step.kind == FILL and rec.reference.code != 0:
                    break
            if out.ended:
                return self._end(out)
            if command:
                earlier.add(command)
            if command == "*S" and step.address is None:
                context_packet = True
            elif command in _PACKET_BREAKERS:
                context_packet = False
        return self._end(out)

    def _end(self, out: Outcome) -> Outcome:
        for side in (self.target, self.reference):
            with contextlib.suppress(TargetNotResponding):
                side.close_example()
        return out

    def _prelude(self) -> None:
        """A unit that lives on between examples (a real one, a co-simulator) is not
        reset by the known state: its index is read on both sides and compared from
        there; and give `>` the same history on both (`SR0`, answered 0,00 by both). The
        reference, a fresh unit, first stands a while: the real one's last motion ended
        long ago (a vector right away would otherwise wait the dwell T on one side only),
        and the target's too: the known state may have moved its axes back just before,
        so the sequence begins once the longest dwell T after that has passed."""
        self._same_eeprom()
        self.reference.age(AGE_SECONDS)
        self.target.wait(self.profile.range("T").hi / 1000)
        indexes = []
        for side in (self.target, self.reference):
            side.link.send("SR0")
            r = side.link.send("@")
            try:
                indexes.append(r.dec(0) if r is not None else 0)
            except AssertionError:
                indexes.append(0)
            side.link.send("SR0")
        self._index = IndexBase((indexes[0] - indexes[1]) % 256)
        self.judge = Judge(self.exact, self.judge.rate, self._index.offset)

    def _base_index(self, command: str, context: set[str], rec: Record) -> None:
        """The index is compared from each side's first reading of it (index.py)."""
        self._index.note(command, context, _values(rec.target), _values(rec.reference))
        self.judge = replace(self.judge, index_offset=self._index.offset or 0)

    def _same_eeprom(self) -> None:
        """A real unit's EEPROM holds its own bytes, not a fresh unit's: the reference
        gets the bytes the target was found with (read once; the session puts back what
        an example wrote) where they differ from its own."""
        if self.target.session is None or "ER" not in self.profile.commands:
            return
        if self._eeprom_changes is None:
            found = self.target.session.eeprom_as_found()
            image = self.profile.eeprom          # a fresh unit's: erased, with defaults
            self._eeprom_changes = {a: v for a, v in found.items()
                                    if image.defaults.get(a, image.erased) != v}
        self.reference.write_eeprom(self._eeprom_changes)

    def _follow(self, instant: int) -> None:
        """The reference waits until ``instant`` on the target's clock (if it is behind)."""
        self.reference.wait(max(0, instant - self.reference.now) / 1e9)

    def _sync(self) -> None:
        """Each step starts at the same instant on both sides."""
        self.reference.catch_up(self.target.now)
        if self.exact:
            self.target.catch_up(self.reference.now)

    def _exchange(self, step: Step, out: Outcome) -> Record | None:
        self._sync()
        data = step.frame_bytes(self.target.target.address, self.target.link.checksums)
        rec = Record(step)
        try:
            rec.target = self.target.exchange(data, lines=step.lines, answer=step.answer,
                                              stall=step.stall, body=step.body)
        except SafetyStop as err:
            why = str(err)
            out.refused.append(why if why.startswith(f"{step.body}:") else f"{step}: {why}")
            return None
        except TargetNotResponding as err:
            if self.target.real:       # a fresh unit's silence ends only its example
                raise
            rec.target = Exchange(data, b"", 0, 0, None, step.lines)
            out.ended = str(err)
        out.frames += 1
        if self.exact:
            self.reference.catch_up(rec.target.sent_at)
        try:
            rec.reference = self.reference.exchange(data, lines=step.lines,
                                                    answer=step.answer, stall=step.stall,
                                                    body=step.body)
        except TargetNotResponding as err:
            rec.reference = Exchange(data, b"", 0, 0, None, step.lines)
            out.ended = out.ended or str(err)
        if out.ended and not rec.target.answer and not rec.reference.answer:
            return None
        return rec

    def _difference(self, command: str, rec: Record) -> str | None:
        moving = False
        if not self.exact:
            self._watch_reference()
            if command in ("P", "PF", ">"):
                moving = self._moving_near(rec) if command != ">" else True
        late = self._cut_ns + (self._slack_ns if moving else 0)
        judge = replace(self.judge, rate=self._ceiling.rate * self._factor, slack_ns=late)
        kind = difference(command, rec.target, rec.reference, judge, moving=moving)
        if kind is None:
            rec.alike = alike_because(command, rec.target, rec.reference, judge, moving=moving)
        return kind

    def _retimed(self, command: str, rec: Record | None) -> None:
        """Real time: the reference acts on a frame when the target's exchange began, the
        target somewhere within its latency (the largest an immediate answer took in the
        sequence so far). A frame (or rig input) that changes a running motion's course
        makes the readings while it runs uncertain by the rate times that latency; one
        that stops it short (H, INTA written, an input) the positions at rest too, until
        the vector it cut has run to its end — for good once D or K threw the rest away."""
        if self.exact:
            return
        if rec is not None and command not in _DEFERRED and rec.target.answer:
            self._latency_ns = max(self._latency_ns,
                                   rec.target.received_at - rec.target.sent_at)
        if command in ("D", "K") and self._cut_ns:
            self._lost = True
        if command in _RETIMING and self._idle_since is None:
            self._slack_ns += self._latency_ns
            if command in _STOPPING:
                self._cut_ns += self._latency_ns

    def _watch_reference(self) -> None:
        """Real time: note when the reference was first seen at rest (after each step;
        a late note only makes the comparison more lenient); at rest and not interrupted,
        every vector has reached its end, and when they were acted on no longer shows."""
        rig = self.reference.link.rig
        st6 = 0xFF if rig is None else int(rig.state()["status"][6], 16)
        if st6 & St6.RUN:
            self._idle_since = None
            return
        if self._idle_since is None:
            self._idle_since = self.reference.now
        if not st6 & St6.INTA:
            self._slack_ns = 0
            if not self._lost:
                self._cut_ns = 0

    def _moving_near(self, rec: Record) -> bool:
        """Whether the reading may have been taken while the axes moved on either side:
        the reference had not been at rest for as long as the target's window is wide
        (the target may have processed the frame that much later or earlier)."""
        if self._idle_since is None:
            return True
        width = rec.target.received_at - rec.target.sent_at
        return rec.reference.sent_at - self._idle_since < 2 * width + SETTLE_NS

    def _context(self, step: Step, in_packet: bool) -> set[str]:
        g = load_grammar()["command"]
        name = command_of(step.body)
        entry = g.get(name, g.get(name + "0", {}))
        flags = {
            "other-address": step.address is not None,
            "stalled": step.stall is not None,
            "lower": _has_lower(step.body[:len(name)] if name else step.body),
            "lower-param": bool(name) and _has_lower(step.body[len(name):]),
            "plus": name != "%" and "+" in step.body[len(name):],
            "bad-checksum": step.checksum == "bad" and self.target.link.checksums,
            "no-checksum": step.checksum == "none" and self.target.link.checksums,
            "in-packet": in_packet,
            "extra-param": bool(name) and not entry.get("params") and name not in ("SW6",)
            and step.body.upper() != name,
            "long-decimal": bool(_LONG_DECIMAL.search(step.body)),
        }
        return {k for k, on in flags.items() if on}


#: frames that change the course of a motion: a difference after them is theirs
_COURSE_CHANGERS = ("H", "G", "K", "R", "D", "SW6", "J", "W")
#: what changes a running motion's course at the instant the unit acts on it (an input
#: set by the rig too): in real time that instant is known only within a latency
_RETIMING = ("H", "G", "K", "R", "SW6", "SW", "XM", "XA", "XU", "XD", "input")
#: of those, what stops a motion short of its vectors' ends
_STOPPING = ("H", "SW6", "input")
#: frames answered when their action ends, not at once
_DEFERRED = ("H", "W", "J")


class _Dwell:
    """The modal dwell T and when the reference last took a vector: a frame sent less
    than T after it may have met the vector still in its dwell (spec 10.2), which is what
    a difference there points at, whatever command showed it."""

    def __init__(self, t_ms: int) -> None:
        self.t_ns = t_ms * 1_000_000
        self.vector_at: int | None = None

    def note(self, command: str, body: str, reference: Exchange) -> None:
        if reference.code != 0:
            return
        if command in ("L", "C") and not _ZERO_VECTOR.fullmatch(body.upper()):
            self.vector_at = reference.sent_at
        elif command in _COURSE_CHANGERS:
            self.vector_at = None          # what follows is the halt's, the resume's...
        elif command == "T" and body[1:].isdigit():
            self.t_ns = int(body[1:]) * 1_000_000

    def within(self, t: int) -> bool:
        return self.vector_at is not None and t - self.vector_at < self.t_ns


class _Ceiling:
    """The fastest the reference's axes can have stepped so far in the example (steps/s):
    the highest V it took, raised by the highest override (XM) and by 17/16 for each XU; a
    reference run (W) or the hand wheel (Y) may step at the variant's top rate. A
    reading taken while moving is uncertain by this rate times its window, not by the
    top rate (spec 10.2: a vector cruises at V at most, a short one at B if lower, and
    no ramp or junction exceeds the cruise; B lowers a rate, it never raises one)."""

    def __init__(self, profile: Profile) -> None:
        self.top = profile.max_rate
        self.speed = profile.reset.V
        self.override = max(100, profile.reset.XM) / 100
        self.up = 1.0

    @property
    def rate(self) -> int:
        return min(self.top, math.ceil(self.speed * self.override * self.up))

    def note(self, command: str, body: str, reference: Exchange) -> None:
        if reference.code != 0:
            return
        value = _first_number(body[len(command):])
        if command == "V" and value is not None:
            self.speed = max(self.speed, value)
        elif command == "XM" and value is not None:
            self.override = max(self.override, value / 100)
        elif command == "XU":          # each XU scales the held vectors again
            self.up *= 17 / 16
        elif command in ("W", "Y"):
            self.speed = self.top


def _first_number(params: str) -> int | None:
    try:
        return int(params.split(",")[0])
    except ValueError:
        return None


def _queued(command: str, body: str, reference: Exchange, last: str | None) -> str | None:
    """The last vector the reference queued after ``last``: ``C+C`` when a C followed a C
    (the two meet at a junction, spec 10.2); a D empties the queue."""
    if command == "D" and reference.code == 0:
        return None
    if command not in ("L", "C") or reference.code != 0 or _ZERO_VECTOR.fullmatch(body.upper()):
        return last
    return "C+C" if command == "C" and last in ("C", "C+C") else command


def _has_lower(text: str) -> bool:
    return any("a" <= ch <= "z" for ch in text)


def _values(exchange: Exchange) -> list[str]:
    return [] if exchange.response is None else list(exchange.response.values)


def _code(exchange: Exchange) -> int | None:
    return None if exchange.code is None else exchange.code & 7


# -- the search -------------------------------------------------------------------------------
@dataclass
class Finding:
    """One disagreement, shrunk: its minimal sequence and how it went."""

    steps: list[Step]
    outcome: Outcome

    @property
    def disagreement(self) -> Disagreement:
        assert self.outcome.disagreement is not None
        return self.outcome.disagreement

    @property
    def frames(self) -> int:
        return self.outcome.frames


@dataclass
class Budget:
    """How long the search may go on: examples, seconds, or both."""

    examples: int | None = 300
    seconds: float | None = None
    start: float = field(default_factory=time.perf_counter)
    used: int = 0
    frames: int = 0

    def spent(self) -> bool:
        if self.examples is not None and self.used >= self.examples:
            return True
        return self.seconds is not None and time.perf_counter() - self.start >= self.seconds

    @property
    def elapsed(self) -> float:
        return time.perf_counter() - self.start


def _again(pair: Pair, finding: Finding, budget: Budget) -> bool:
    """Real time: whether the shrunk sequence disagrees the same way once more (a
    disagreement seen once may be the timing of that run, not the target)."""
    trial = pair.run(finding.steps)
    budget.frames += trial.frames
    d = trial.disagreement
    return d is not None and d.signature == finding.disagreement.signature


#: at most this many runs for the last pass over a shrunk sequence
MINIMISE_RUNS = 300


def minimise(pair: Pair, finding: Finding, budget: Budget, *,
             frames_only: bool = False) -> Finding:
    """Hypothesis shrinks by its own measure (the choices it drew); this last pass makes
    each step the least the same command still disagrees the same way with, so the
    transcript and the steps its label reads are what the disagreement needs: a step
    taken out, else sent plain (its own checksum, no stall), else replaced by a wait as
    long as its exchange took (a frame that only let time pass); two fills of one frame
    or two waits become one, a fill is tried half as full. With ``frames_only`` a frame
    may only be taken out: waits and fills stay as they are."""
    steps, outcome = finding.steps, finding.outcome
    want = (outcome.disagreement.command, outcome.disagreement.kind)
    runs = 0

    def same(candidate: list[Step]):
        """The candidate's outcome when it disagrees as the finding does, else None."""
        nonlocal runs
        runs += 1
        trial = pair.run(candidate)
        budget.frames += trial.frames
        d = trial.disagreement
        return trial if d is not None and (d.command, d.kind) == want else None

    i = 0
    while i < len(steps) and runs < MINIMISE_RUNS:
        found = False
        lesser = ([steps[:i] + steps[i + 1:]] if steps[i].kind == FRAME else []) \
            if frames_only else _lesser(steps, i, outcome)
        for candidate in lesser:
            if (trial := same(candidate)) is not None:
                steps, outcome, found = candidate, trial, True
                break
        if not found:
            i += 1
    return Finding(steps, outcome)


def _lesser(steps: list[Step], i: int, outcome: Outcome) -> Iterator[list[Step]]:
    """Sequences with step ``i`` made less, most reduced first."""
    s = steps[i]
    nxt = steps[i + 1] if i + 1 < len(steps) else None
    if nxt is not None and s.kind in (FILL, WAIT) and replace(nxt, times=s.times,
                                                              seconds=s.seconds) == s:
        joined = (replace(s, times=s.times + nxt.times) if s.kind == FILL
                  else replace(s, seconds=round(s.seconds + nxt.seconds, 5)))
        yield [*steps[:i], joined, *steps[i + 2:]]
    if s.kind == FILL and s.times > 1:
        yield [*steps[:i], replace(s, times=s.times // 2), *steps[i + 1:]]
    yield steps[:i] + steps[i + 1:]
    if s.kind == FRAME and (s.checksum != "auto" or s.stall is not None):
        yield [*steps[:i], replace(s, checksum="auto", stall=None), *steps[i + 1:]]
    last = outcome.disagreement.index if outcome.disagreement else len(outcome.records)
    took = sum(r.reference.received_at - r.reference.sent_at
               for r in outcome.records[:last] if r.place == i and r.reference is not None)
    if s.kind in (FRAME, FILL) and took > 0:
        prev = steps[i - 1] if i > 0 else None
        if prev is not None and prev.kind == WAIT:      # the wait before takes it in
            longer = replace(prev, seconds=round(prev.seconds + took / 1e9, 5))
            yield [*steps[:i - 1], longer, *steps[i + 1:]]
        yield [*steps[:i], Step(WAIT, seconds=round(took / 1e9, 5)), *steps[i + 1:]]


class _Spent(Exception):
    """The budget ran out inside Hypothesis."""


@contextlib.contextmanager
def _seed_alone() -> Iterator[None]:
    """Hypothesis now and then draws a constant found in the source of the modules the
    process has imported: which modules those are (a test run's, a CLI's) would decide
    the sequences as much as the seed. The pool is emptied while the search runs (an
    internal of Hypothesis: where it is missing there is nothing to empty)."""
    pool = getattr(providers, "_get_local_constants", None)
    cache = getattr(providers, "CONSTANTS_CACHE", None)
    if pool is None or cache is None:
        yield
        return
    empty = Constants()
    cache.cache.clear()
    providers._get_local_constants = lambda: empty
    try:
        yield
    finally:
        providers._get_local_constants = pool
        cache.cache.clear()


def search(pair: Pair, options: Options, budget: Budget, *, seed: int = 0,
           stop_after: int | None = None, with_probes: bool = True,
           on_finding: Callable[[Finding], None] | None = None) -> list[Finding]:
    """Disagreements between the pair's sides, each shrunk and kept once (by its rule
    and kind), until the budget is spent (or ``stop_after`` findings): first the probes
    (unless ``with_probes`` is false), each run whole, then the sequences Hypothesis
    draws."""
    findings: list[Finding] = []
    known: set[tuple] = set()

    def more() -> bool:
        return not budget.spent() and (stop_after is None or len(findings) < stop_after)

    def keep(found: Finding, *, written: bool = False) -> None:
        """A disagreement made minimal, confirmed in real time, kept once. A probe
        (``written``) in real time only loses the frames it does not need (its waits and
        slow rates are what make it show beyond the timing band), and stays as written
        unless the lesser one shows again."""
        finding = minimise(pair, found, budget, frames_only=written and not pair.exact)
        if finding.disagreement.signature in known:
            return
        known.add(finding.disagreement.signature)
        confirmed = pair.exact or _again(pair, finding, budget)
        if not confirmed and written and finding.steps != found.steps:
            finding = found
            confirmed = _again(pair, found, budget)
        if not confirmed:
            pair.unconfirmed.append(finding)
            return
        findings.append(finding)
        if on_finding is not None:
            on_finding(finding)

    grammar = Grammar(pair.profile, options)
    for _, steps in grammar.probes() if with_probes else ():
        if not more():
            return findings
        budget.used += 1
        outcome = pair.run(steps)
        budget.frames += outcome.frames
        d = outcome.disagreement
        if d is not None and d.signature not in known:
            keep(Finding(steps, outcome), written=True)

    strategy = grammar.sequences()
    rounds = 0
    while more():
        best: dict[str, Finding] = {}

        def fails(steps: list[Step], best: dict[str, Finding] = best) -> bool:
            if budget.spent():
                raise _Spent           # also while shrinking: the smallest seen is kept
            budget.used += 1
            outcome = pair.run(steps)
            budget.frames += outcome.frames
            d = outcome.disagreement
            if d is None or d.signature in known:
                return False
            found = Finding(list(steps), outcome)
            if "found" not in best or frames_in(steps) <= frames_in(best["found"].steps):
                best["found"] = found
            if budget.spent():
                raise _Spent       # shrinking stops here: the smallest seen is kept
            return True

        left = (budget.examples - budget.used) if budget.examples is not None else 10**6
        # Hypothesis's own defaults, not whatever profile the process loaded (the suite's
        # pytest plugin loads derandomized ones): the seed alone decides the sequences
        chosen = settings(settings.get_profile("default"), derandomize=False,
                          max_examples=max(1, left), database=None, deadline=None,
                          phases=(Phase.generate, Phase.shrink), report_multiple_bugs=False,
                          suppress_health_check=list(HealthCheck))
        try:
            with _seed_alone():
                find(strategy, fails, settings=chosen, random=random.Random(seed + rounds))
        except (NoSuchExample, _Spent):
            pass
        except Flaky:
            # real time: a disagreement Hypothesis could not see again (kept below only
            # if it shows once more)
            pass
        rounds += 1
        if "found" not in best:
            if budget.spent() or budget.examples is not None:
                break                  # (with examples left: Hypothesis found nothing new)
            continue
        keep(best["found"])
    return findings
