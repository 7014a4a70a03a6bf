"""The differential engine: a sequence of steps sent to a target and a reference alike,
answer by answer compared; Hypothesis draws the sequences from the grammar and shrinks
each disagreement to a minimal sequence, which is labelled, graded and kept once.

A sequence stops at its first disagreement: after it the two sides are in different
states and everything later would differ too.
"""

from __future__ import annotations

import contextlib
import random
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field, replace

from hypothesis import HealthCheck, Phase, find, settings
from hypothesis.errors import Flaky, NoSuchExample

from conformance.diff.compare import Judge, alike_because, difference
from conformance.diff.course import Course
from conformance.diff.grammar import Grammar, Options
from conformance.diff.index_base import QUERIES, IndexBase
from conformance.diff.labels import allowed, command_of, label, verdict_of
from conformance.diff.matrix import Cell, cells
from conformance.diff.reach import Reach
from conformance.diff.rigstate import observed, response
from conformance.diff.sides import RoundTrip, Side
from conformance.diff.start import Start, left_summing
from conformance.diff.step_flags import step_flags
from conformance.diff.steps import FILL, FRAME, INPUT, RIG, STATE, WAIT, Step, frames_in
from conformance.diff.timing import timing_for
from conformance.diff.told import Teller
from conformance.link.liveness import TargetNotResponding
from conformance.link.stops import SafetyStop
from conformance.motion.tolerance import (
    PLACEMENT_STEPS,
    TICK_NS,
    byte_ns,
    step_period,
)
from conformance.protocol.catalogue import classes
from conformance.targets.session import StepFailed
from conformance.verdicts.verdict import CouldNotTest
from gve_fixtures.profile import Profile
from gve_fixtures.protocol import ErrorCode, St6

#: the frames that change a running motion's course (H, G, XA...)
_COURSE = classes(retimes=True)
#: frames that end an open packet before its *E (spec 7, our reading [D])
_BREAKERS = classes(packet="breaker")


@dataclass
class StepRecord:
    """One step as it went: the step, the frame's bytes and both sides' exchanges."""

    step: Step
    target: RoundTrip | None = None
    reference: RoundTrip | None = None
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
    target: RoundTrip
    reference: RoundTrip
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
class ExampleRun:
    """One example run on both sides: its steps as they went, and where they disagreed."""

    records: list[StepRecord] = field(default_factory=list)
    disagreement: Disagreement | None = None
    frames: int = 0
    refused: list[str] = field(default_factory=list)     # steps the guard did not send
    inputs: dict[int, int] = field(default_factory=dict)  # each port as the rig last set it
    ended: str = ""                                      # why the sequence ended early
    begun: bool = False                  # both sides were brought to the known state


class Pair:
    """A target and its reference, run step by step."""

    def __init__(self, target: Side, reference: Side, profile: Profile) -> None:
        self.target = target
        self.reference = reference
        self.profile = profile
        self.timing = timing_for(target, reference)
        # the fastest an axis's counter can change: the variant's top rate, in counter
        # units (GVE54: a coarse micro-step mode moves several sixteenths a step)
        self._factor = max(profile.microstep.factors.values()) if profile.microstep else 1
        # somebody else's unit places its steps its own way, even in virtual time
        placement = 0 if target.target.info.strict else PLACEMENT_STEPS
        self.judge = Judge(exact=self.timing.exact, rate=profile.max_rate * self._factor,
                           placement=placement,
                           unused_inputs=tuple(profile.unused_inputs.items()))
        self.course = Course(profile)
        self.timing.reach = self._reading_ns
        #: the frames of the example that changed a motion's course (H, G, XA...): a unit
        #: of somebody else's may take each at its own next step
        self._course_changes = 0
        self.start = Start(target, reference, profile, self.timing)
        self._index = IndexBase()
        #: real time: disagreements seen once that their sequence did not show again
        self.unconfirmed: list[Finding] = []
        #: a co-simulator is told each sequence's frames ahead where the guard can judge
        #: them (told.py); False: one exchange a frame
        self.ahead = True
        #: a co-simulator that keeps a state (`snapshot`, docs/cosim.md): its first unit
        #: powered on is kept, and each next sequence begins from it restored instead of
        #: powered on (the same findings, fewer commands). Off by default: a restore
        #: never shows a power-on that leaves something behind (only the first is run),
        #: and the emulator's restore (a fork) costs more than its power-on
        self.restores = False
        self._teller: Teller | None = None     # the example's frames told ahead
        #: virtual time: the step whose rig read agreed last, and both sides' instants then
        self._seen: tuple[int, int, int] | None = None
        #: when the search's time is up (``--seconds``): a sequence stops between steps
        self.out_of_time: Callable[[], bool] = _never
        #: what the sequences reached (commands, table values, states), if counted
        self.reach: Reach | None = None
        #: why the target could not be brought to the known state after a sequence ("":
        #: it could); no sequence is sent to it after that
        self.lost = ""
        self._last: list[Step] = []            # the steps of the latest sequence begun
        #: the latest sequence began at the target's power-on (Start.powered)
        self.started_at_power_on = False
        self.led_there: list[Step] = []        # the sequence after which it was lost

    @property
    def exact(self) -> bool:
        """Both sides in virtual time: every difference, timing too, is one."""
        return self.timing.exact

    # -- one example ----------------------------------------------------------------------
    def run(self, steps: list[Step]) -> ExampleRun:
        """The example on both sides; against a co-simulator its frames told ahead
        (told.py), and redone frame by frame where the target drifted from them."""
        out = self._run(steps, ahead=self.ahead and self.exact and self.target.real)
        if self._teller is not None and self._teller.drifted:
            out = self._run(steps, ahead=False)
        return out

    def _run(self, steps: list[Step], *, ahead: bool) -> ExampleRun:
        out = ExampleRun()
        self._teller = None
        self._seen = None
        if not self._begin(out):
            return out
        self._last = list(steps)
        self._teller = Teller(self.target, steps, self._refer) if ahead else None
        earlier: set[str] = set()          # what the sequence did before (labels read it)
        try:
            for place, step in enumerate(steps):
                if self.out_of_time():
                    out.ended = "the search's time ran out"
                    break
                if step.kind == WAIT:
                    self.target.wait(step.seconds, self.timing.waiting(step.seconds))
                    self.timing.waited()
                    out.records.append(StepRecord(step, place=place))
                elif step.kind == INPUT:
                    self._input(step, place, out, earlier)
                elif step.kind == RIG:
                    self._rig_act(step, place, out, earlier)
                elif step.kind == STATE:
                    if self._rig_state(step, place, out, earlier):
                        break
                elif self._frames(step, place, out, earlier):
                    break
            else:
                # what the rig sees at the end, whatever the sequence's last read was;
                # in virtual time a read the sequence ended with, at this very instant on
                # both sides, is what the rigs see at the end: nothing has happened since
                if out.ended:
                    pass
                elif self._seen == (len(steps) - 1, self.target.now, self.reference.now):
                    out.records.append(StepRecord(Step(STATE), place=len(steps)))
                else:
                    self._rig_state(Step(STATE), len(steps), out, earlier)
            if self._teller is not None:
                self._teller.finish()
            self._left_summing(out)
        except BaseException:
            if self._teller is not None:
                self._teller.forget()
            raise
        return self._end(out)

    def _left_summing(self, out: ExampleRun) -> None:
        """A disagreement whose sequence a power-on left summing (start.py's
        left_summing) is the reset state's (context `summing-after-power-on`: checksums
        off after power-on, 9.reset.state [M])."""
        d = out.disagreement
        if d is None or not left_summing([r.step for r in out.records[:d.index]],
                                         self.started_at_power_on, self.target.link):
            return
        d.context = d.context | {"summing-after-power-on"}
        d.rule = label(d.command, d.kind, set(d.context), set(d.earlier), _code(d.reference),
                       _code(d.target), self.profile.family)
        d.verdict, d.tag = verdict_of(d.rule, self.target.target.info.strict)

    def _begin(self, out: ExampleRun) -> bool:
        """Both sides in the known state, or both from power-on where the target is a
        co-simulator in virtual time (start.py); False when the guard refused it, or when
        the target could not be brought there (:attr:`lost`)."""
        if self.lost:
            out.ended = self.lost
            return False
        try:
            self._course_changes = 0
            self.started_at_power_on = self.target.real and self.start.powered(self.restores)
            if self.started_at_power_on:
                self._index = IndexBase()
                self.judge = replace(self.judge, index_offset=0)
            else:
                self._index = self.start.known()
                if self.target.real:
                    self.judge = replace(self.judge, index_offset=self._index.offset)
        except SafetyStop as err:
            # the known state or the reads after it were refused (a minimiser's candidate
            # left the unit where the guard cannot bring it back, or the guard saw the
            # unit restart there): the candidate shows nothing
            out.refused.append(f"the known state: {err}")
            return False
        except StepFailed as err:
            # the frames before left the unit where the manual's rules cannot bring it to
            # rest, where the reference's were (the session names the rule where its
            # evidence broke one): nothing more is sent, and the search ends there
            # (KnownStateLost)
            self.lost = out.ended = f"the known state could not be had: {err}"
            self.led_there = self._last
            return False
        self.course = Course(self.profile)
        out.begun = True
        return True

    def _input(self, step: Step, place: int, out: ExampleRun, earlier: set[str]) -> None:
        """A rig input set on both sides (left out where a side has no rig)."""
        if not (self.target.has_rig and self.reference.has_rig):
            return
        sent_at = self.target.now
        done = self.target.set_input(step.port, step.value)
        # the target's rig acted somewhere before its `ok`, the reference's at once
        self.timing.retimed("input", RoundTrip(b"", b"ok" * done, sent_at, self.target.now,
                                               None))
        if done and self.reference.set_input(step.port, step.value):
            out.inputs[step.port] = step.value
            out.records.append(StepRecord(step, place=place))
            earlier.add("input")
            if self.reach is not None:
                self.reach.took(step, None)

    def _rig_act(self, step: Step, place: int, out: ExampleRun, earlier: set[str]) -> None:
        """Another act of the rigs' hands on both sides alike (a power-on, a reference
        switch placed or taken off), left out where a side has no rig. After a power-on
        both sides' index counts from 0 again (spec 9)."""
        if not (self.target.has_rig and self.reference.has_rig):
            return
        if self._teller is not None:
            self._teller.finish()          # the frames told ahead are all taken first
        sent_at = self.target.now
        done = self.target.rig_act(step.body)
        self.timing.retimed("input", RoundTrip(b"", b"ok" * done, sent_at, self.target.now,
                                               None))
        if done and self.reference.rig_act(step.body):
            out.records.append(StepRecord(step, place=place))
            earlier.add(step.body.split()[0])
            if step.body == "power-on":
                self.course.powered_on()
                self._index = IndexBase(0)
                self.judge = replace(self.judge, index_offset=0)

    def _rig_state(self, step: Step, place: int, out: ExampleRun, earlier: set[str]) -> bool:
        """What the rigs see of both sides (outputs, spindle, where the axes are),
        compared as answers are (rigstate.py); True when they disagree (the example ends
        there). Left out where a side has no rig, or its rig does not say."""
        if not (self.target.has_rig and self.reference.has_rig):
            return False
        if self._teller is not None:
            self._teller.finish()          # the frames told ahead are all taken first
        self.timing.align()
        seen = self.target.rig_state()
        known = self.reference.rig_state() if seen is not None else None
        if known is None:
            return False
        for labelled, compared, a, b in observed(seen, known):
            if compared == "PF" and not (self.exact and self.target.target.info.strict):
                # where the axes are is compared only where both sides are exact and one
                # reading (our own emulator, --strict): in real time the two rigs are read
                # at instants nobody can pair, and somebody else's motion differs within
                # readings the position reads already grade by their own rules
                continue
            rec = StepRecord(step, place=place)
            rec.target = RoundTrip(labelled.encode(), a, 0, 0, response(a))
            rec.reference = RoundTrip(labelled.encode(), b, 0, 0, response(b))
            kind = self._difference(compared, rec)
            if kind is not None:
                out.records.append(rec)
                out.disagreement = self._disagreement(step, labelled, kind, out, earlier)
                return True
        out.records.append(StepRecord(step, place=place))
        if self.exact:
            self._seen = (place, self.target.now, self.reference.now)
        return False

    def _frames(self, step: Step, place: int, out: ExampleRun, earlier: set[str]) -> bool:
        """A frame (a fill: until the queue is full) to both sides; True when the example
        ends here (a disagreement, a side silent for good)."""
        command = command_of(step.body)
        times = step.times if step.kind == FILL else 1
        for i in range(times):
            rec = self._exchange(step, out, place, i)
            if rec is None:
                break
            rec.repeat, rec.place = i, place
            out.records.append(rec)
            self.timing.retimed(command, rec.target, rec.reference)
            if command in QUERIES:
                self._base_index(command, self._context(step, self.course.in_packet), rec)
            kind = self._difference(command, rec)
            if kind is not None:
                out.disagreement = self._disagreement(step, command, kind, out, earlier)
                return True
            if (rec.reference.code or 0) & 7:
                self._index.refused_frame(command, self._context(step, self.course.in_packet))
            if command in _BREAKERS and self.course.in_packet:
                earlier.add("packet-broken")
            self.course.exchanged(step, rec.reference)
            self.course.took(command, step.body, rec.reference, first=i == 0)
            if self.course.junction:
                earlier.add("junction")
            if self.reach is not None:
                self.reach.took(step, rec.reference)
            if step.kind == FILL and rec.reference.code != ErrorCode.OK:
                break
        if out.ended:
            return True
        if command:
            # the spindle's V is not the feed rate's: a read after it names the spindle
            spindle = self.profile.spindle
            to_spindle = spindle is not None and step.address == spindle.address
            earlier.add("spindle" if to_spindle else command)
            if command in _COURSE:
                self._course_changes += 1
            code = (rec.reference.code or 0) & 7 if rec is not None else 0
            if code:
                earlier.add(f"{command}-refused")
            if code == ErrorCode.QUEUE_FULL:
                earlier.add(f"{command}-no-room")
        return False

    def _disagreement(self, step: Step, command: str, kind: str, out: ExampleRun,
                      earlier: set[str]) -> Disagreement | None:
        """The last record's difference, in its context, labelled and graded (None: the
        spec allows both answers, and the example ends there)."""
        rec = out.records[-1]
        context = self._context(step, self.course.in_packet)
        context |= self.course.context(rec.reference.sent_at, command, step.body,
                                       _values(rec.target) if kind == "position" else None)
        if kind == "position" and _placed(rec, self.judge.placement, self._course_changes):
            context.add("placement")
        elif "beyond-reach" not in context and self.timing.within(
                command, step.body, kind, rec.target, rec.reference,
                self.course.rate * self.course.factor, self.course.heading,
                self._reading_ns(command, step.body)):
            context.add("profile")
        if _ran(rec.reference, self.reference.link.baud):
            context.add("after-run")
        context |= _st6_differs(step.body, rec)
        if _released(out):
            context.add("released")
        if command == "@":
            context |= self._index.context(_values(rec.target), _values(rec.reference))
        family = self.profile.family
        why = allowed(command, kind, context, earlier, _code(rec.reference), _code(rec.target),
                      family)
        if why is not None:
            out.ended = f"both answers allowed: {why}"
            return None
        d = Disagreement(len(out.records) - 1, command, kind, rec.target, rec.reference,
                         frozenset(context), frozenset(earlier))
        d.rule = label(command, kind, context, earlier, _code(rec.reference),
                       _code(rec.target), family)
        d.verdict, d.tag = verdict_of(d.rule, self.target.target.info.strict)
        return d

    def _end(self, out: ExampleRun) -> ExampleRun:
        for side in (self.target, self.reference):
            with contextlib.suppress(TargetNotResponding):
                side.close_example()
        return out

    def _reading_ns(self, command: str = "", body: str = "") -> tuple[int, int]:
        return self.course.reading_ns(self._course_changes, command, body)

    def _base_index(self, command: str, context: set[str], rec: StepRecord) -> None:
        """The index is compared from each side's first reading of it (index_base.py)."""
        self._index.note(command, context, _values(rec.target), _values(rec.reference))
        self.judge = replace(self.judge, index_offset=self._index.offset or 0)

    def _refer(self, step: Step, data: bytes) -> tuple[RoundTrip, str]:
        """The frame to the reference, listened to as long as the target is: its exchange,
        and why the sequence ends there ("": it goes on)."""
        try:
            return self.reference.exchange(data, lines=step.lines, answer=step.answer,
                                           stall=step.stall, body=step.body,
                                           like=self.target), ""
        except TargetNotResponding as err:
            return RoundTrip(data, b"", 0, 0, None, step.lines), str(err)

    def _exchange(self, step: Step, out: ExampleRun, place: int = 0,
                  repeat: int = 0) -> StepRecord | None:
        # a quiet line after a timed-out frame is waited for before either side acts
        self.target.link.settle()
        teller = self._teller
        if teller is None or not teller.queue:
            self.timing.align()
            if teller is not None:
                teller.tell(place, repeat)
        data = step.frame_bytes(self.target.target.address, self.target.link.checksums)
        told = teller.take(data) if teller is not None else None
        rec = StepRecord(step)
        sent_at = self.target.now
        ended: list[str] = []

        def reference() -> None:
            """The frame to the reference, as the target's exchange began; done while the
            target runs it where its port sends a write before its read."""
            self.timing.sent(sent_at)
            rec.reference, why = self._refer(step, data)
            if why:
                ended.append(why)

        if told is not None:               # answered by the reference ahead already
            rec.reference = told.reference
            if told.ended:
                ended.append(told.ended)
        try:
            rec.target = self.target.exchange(data, lines=step.lines, answer=step.answer,
                                              stall=step.stall, body=step.body,
                                              meanwhile=reference if told is None else None)
        except SafetyStop as err:
            why = str(err)
            out.refused.append(why if why.startswith(f"{step.body}:") else f"{step}: {why}")
            if told is not None:
                teller.drifted = True
            return None
        except TargetNotResponding as err:
            if self.target.real:       # a fresh unit's silence ends only its example
                raise
            rec.target = RoundTrip(data, b"", 0, 0, None, step.lines)
            out.ended = str(err)
        out.frames += 1
        if teller is not None and told is not None:
            teller.check(told, rec.target)
        if teller is not None and teller.drifted:
            out.ended = "the target's answers drifted from the frames told ahead"
            return None                    # the example is redone frame by frame
        if rec.reference is None:
            reference()
        out.ended = out.ended or (ended[0] if ended else "")
        if out.ended and not rec.target.answer and not rec.reference.answer:
            return None
        return rec

    def _context(self, step: Step, in_packet: bool) -> set[str]:
        return step_flags(step, self.profile, in_packet=in_packet,
                          summing=self.target.link.checksums)

    def _difference(self, command: str, rec: StepRecord) -> str | None:
        moving, late = self.timing.allowance(command, rec.target, rec.reference)
        judge = replace(self.judge, rate=self.course.rate * self._factor, slack_ns=late,
                        line=self.timing.line(),
                        period_ns=step_period(self.course.accel) if self.judge.placement else 0)
        kind = difference(command, rec.target, rec.reference, judge, moving=moving)
        if kind is None:
            rec.alike = alike_because(command, rec.target, rec.reference, judge, moving=moving)
        return kind



#: the frames whose answer's value is ST6 (F's with its queue bit)
_ST6_READS = ("SR6", "F")


def _placed(rec: StepRecord, placement: int, changes: int) -> bool:
    """Whether a target of somebody else's reads within another placement of the same
    steps: ``placement`` steps, and as many more for each of the ``changes`` of the
    motion's course in the example, which it may take at its own next step."""
    if not placement:
        return False
    a, b = _values(rec.target), _values(rec.reference)
    try:
        apart = [abs(int(x) - int(y)) for x, y in zip(a, b, strict=True)]
    except ValueError:
        return False
    return max(apart, default=0) <= placement * (1 + changes)


def _ran(reference: RoundTrip, baud: int) -> bool:
    """Whether the reference answered a tick or more later than the bytes take: after a
    run of its own (a W that met no switch), not at once (a value out of range)."""
    if not reference.answer:
        return False
    lasted = reference.received_at - reference.sent_at
    return lasted > (len(reference.sent) + len(reference.answer)) * byte_ns(baud) + TICK_NS


def _st6_differs(body: str, rec: StepRecord) -> set[str]:
    """The ST6 bits two answers to a read of ST6 differ in (``st6-run``, ``st6-inta``,
    …): which part of the state the sequence left differs."""
    if body not in _ST6_READS:
        return set()
    try:
        words = [int(_values(x)[0], 16) for x in (rec.target, rec.reference)]
    except (IndexError, ValueError):
        return set()
    differ = words[0] ^ words[1]
    return {"st6-" + bit.name.lower().replace("_", "-") for bit in St6 if differ & bit}


#: the status words that set the inputs' polarity (an unconnected input made active)
_POLARITY = ("SW2,", "SW3,")


def _released(out: ExampleRun) -> bool:
    """The rig grounded inputs and has released them all, no polarity written: no input
    is active, so nothing interrupts again after a clear."""
    return bool(out.inputs) and all(v == 0xFF for v in out.inputs.values()) and not any(
        r.step.kind == FRAME and r.step.body.startswith(_POLARITY) for r in out.records)


def _values(exchange: RoundTrip) -> list[str]:
    return [] if exchange.response is None else list(exchange.response.values)


def _code(exchange: RoundTrip) -> int | None:
    return None if exchange.code is None else exchange.code & 7


# -- the search -------------------------------------------------------------------------------
@dataclass
class Finding:
    """One disagreement, shrunk: its minimal sequence and how it went."""

    steps: list[Step]
    outcome: ExampleRun
    number: int = 0                    # the search's count of disagreements seen, from 1
    #: why it was not shrunk or replayed as far as others ("": it was)
    unreplayed: str = ""

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
        return self.out_of_time()

    def out_of_time(self) -> bool:
        """``--seconds`` passed: no further sequence, shrink or step begins."""
        return self.seconds is not None and time.perf_counter() - self.start >= self.seconds

    @property
    def elapsed(self) -> float:
        return time.perf_counter() - self.start


def _again(pair: Pair, finding: Finding, budget: Budget) -> bool:
    """Real time: whether the shrunk sequence disagrees the same way once more (a
    disagreement seen once may be the timing of that run, not the target). A run whose
    known state the guard refused (the finding's own run left the counters where its
    frames could not put them, say) tried nothing: it is run once more."""
    for _ in range(2):
        trial = pair.run(finding.steps)
        budget.frames += trial.frames
        if trial.begun or pair.lost:
            break
    d = trial.disagreement
    return d is not None and d.signature == finding.disagreement.signature


#: at most this many runs for the last pass over a shrunk sequence
MINIMISE_RUNS = 300
_RESTARTS = classes(restart=True)


def minimise(pair: Pair, finding: Finding, budget: Budget, *,
             frames_only: bool = False) -> Finding:
    """The last pass over a disagreement, for what Hypothesis's shrinking cannot do.
    Hypothesis shrinks the choices it drew, by its own measure, to any disagreement not
    kept yet; it cannot (1) shrink a written sequence at all (the probes, the tables'
    sweep and the matrix's cells are run as written: there are no choices to shrink),
    (2) put in a value the run only tells, a frame replaced by a wait as long as its
    exchange took (a frame that only let time pass, which a motion's timing may need),
    nor join two steps into one whose value is their sum (two waits, two fills of one
    frame), and (3) hold to the disagreement it began with (the same command and kind):
    what it shrinks to may be another, which the transcript would then not show.
    tests/conformance/diff/test_engine.py shows each: a probe left as written is longer,
    and a drawn sequence Hypothesis alone left keeps frames that a wait stands for here.

    Each step is made the least the same command still disagrees the same way with, so
    the transcript and the steps its label reads are what the disagreement needs: a step
    taken out, else sent plain (its own checksum, no stall), else replaced by a wait as
    long as its exchange took; two fills of one frame or two waits become one, a fill is
    tried half as full; the pass is repeated until it changes nothing. With
    ``frames_only`` a frame may only be taken out: waits and fills stay as they are."""
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

    # passes until one changes nothing: a step that could not go while a later one was
    # there may go once that one has
    changed = True
    while changed:
        changed, i = False, 0
        while i < len(steps) and runs < MINIMISE_RUNS and not budget.out_of_time() \
                and not pair.lost:
            found = False
            lesser = ([steps[:i] + steps[i + 1:]] if steps[i].kind == FRAME else []) \
                if frames_only else _lesser(steps, i, outcome)
            for candidate in lesser:
                if (trial := same(candidate)) is not None:
                    steps, outcome, found, changed = candidate, trial, True, True
                    break
            if not found:
                i += 1
    return Finding(steps, outcome)


def _lesser(steps: list[Step], i: int, outcome: ExampleRun) -> Iterator[list[Step]]:
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
    if not _restarts_wait(steps, i):
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


def _restarts_wait(steps: list[Step], i: int) -> bool:
    """Step ``i`` is the wait out of a restart: without it the next frames go to a unit
    that is deaf while it restarts, and a unit that lives on between sequences is then
    silent for the run's guard (no host sends so; a target right to be deaf)."""
    before = steps[i - 1] if i > 0 else None
    return steps[i].kind == WAIT and before is not None and (
        (before.kind == FRAME and command_of(before.body) in _RESTARTS)
        or (before.kind == RIG and before.body == "power-on"))


#: sequences in a row that sent no frame before the search ends COULD-NOT-TEST: it never
#: goes on, or passes, on sequences that did not run
IDLE_MOST = 20


class _Spent(Exception):
    """The budget ran out inside Hypothesis."""


def _settings(examples: int) -> settings:
    """Hypothesis's own defaults, not whatever profile the process loaded (the suite's
    pytest plugin loads derandomized ones): the seed decides the sequences (with the
    constants Hypothesis now and then draws from the source of the modules the process
    imported: the same in every run of one command, docs/diff.md)."""
    return settings(settings.get_profile("default"), derandomize=False,
                    max_examples=max(1, examples), database=None, deadline=None,
                    phases=(Phase.generate, Phase.shrink), report_multiple_bugs=False,
                    suppress_health_check=list(HealthCheck))


class _Search:
    """One search's findings, the signatures already kept, and its budget."""

    def __init__(self, pair: Pair, budget: Budget, stop_after: int | None,
                 on_finding: Callable[[Finding], None] | None,
                 on_seen: Callable[[Finding], None] | None = None,
                 on_dropped: Callable[[Finding], None] | None = None) -> None:
        self.pair = pair
        self.budget = budget
        self.stop_after = stop_after
        self.on_finding = on_finding
        self.on_seen = on_seen
        self.on_dropped = on_dropped
        self.findings: list[Finding] = []
        self.known: set[tuple] = set()
        self.seen = 0                  # disagreements seen so far (each one's number)
        self.idle = 0                  # sequences in a row that sent no frame
        self.skipped = 0               # sequences that sent no frame (not counted)

    def more(self) -> bool:
        return not self.pair.lost and not self.budget.spent() and (
            self.stop_after is None or len(self.findings) < self.stop_after)

    def trial(self, steps: list[Step]) -> Finding | None:
        """One example run whole; a finding when it shows a disagreement not kept yet. A
        sequence that sent no frame (its start refused, say) is not counted in the
        budget; :data:`IDLE_MOST` of them in a row end the search (:attr:`Pair.lost`)."""
        outcome = self.pair.run(steps)
        self.budget.frames += outcome.frames
        if outcome.frames:
            self.budget.used += 1
            self.idle = 0
        else:
            self.idle += 1
            self.skipped += 1
            if self.idle >= IDLE_MOST and not self.pair.lost:
                why = (outcome.refused or [outcome.ended or "nothing was sent"])[0]
                self.pair.lost = (f"{IDLE_MOST} sequences in a row sent no frame: {why}")
                self.pair.led_there = list(steps)
        d = outcome.disagreement
        if d is None or d.signature in self.known:
            return None
        return Finding(list(steps), outcome)

    def draw(self, strategy, seed: int) -> Finding | None:
        """One round of Hypothesis: the smallest new disagreement it saw (None: none)."""
        best: Finding | None = None

        def fails(steps: list[Step]) -> bool:
            nonlocal best
            if self.budget.spent() or self.pair.lost:
                raise _Spent           # also while shrinking: the smallest seen is kept
            found = self.trial(steps)
            if found is None:
                return False
            if best is None or frames_in(steps) <= frames_in(best.steps):
                best = found
            if self.budget.spent():
                raise _Spent       # shrinking stops here: the smallest seen is kept
            return True

        b = self.budget
        left = (b.examples - b.used) if b.examples is not None else 10**6
        try:
            find(strategy, fails, settings=_settings(left), random=random.Random(seed))
        except (NoSuchExample, _Spent):
            pass
        except Flaky:
            # real time: a disagreement Hypothesis could not see again (kept only if it
            # shows once more)
            pass
        return best

    def keep(self, found: Finding, *, written: bool = False) -> None:
        """A disagreement made minimal, confirmed in real time, kept once. A probe
        (``written``) in real time only loses the frames it does not need (its waits and
        slow rates are what make it show beyond the timing band), and stays as written
        unless the lesser one shows again."""
        pair, repeatable = self.pair, self.pair.timing.repeatable
        self.seen += 1
        found.number = self.seen
        if self.on_seen is not None:       # on disk before the shrinking: a kill keeps it
            self.on_seen(found)
        finding = minimise(pair, found, self.budget, frames_only=written and not repeatable)
        finding.number = found.number
        if finding.disagreement.signature in self.known:
            self._dropped(found)
            return
        self.known.add(finding.disagreement.signature)
        confirmed = repeatable or _again(pair, finding, self.budget)
        if not confirmed and written and finding.steps != found.steps and not pair.lost:
            finding = found
            confirmed = _again(pair, found, self.budget)
        if pair.lost:
            # the unit could not be brought back after it: the disagreement stands as
            # seen, and the lost known state is a failure of its own (the session's)
            finding.unreplayed = f"not replayed further: {pair.lost}"
            confirmed = True
        if not confirmed:
            pair.unconfirmed.append(finding)
            self._dropped(found)
            return
        self.findings.append(finding)
        if self.on_finding is not None:
            self.on_finding(finding)

    def _dropped(self, found: Finding) -> None:
        if self.on_dropped is not None:
            self.on_dropped(found)


class KnownStateLost(CouldNotTest):
    """The target could not be brought to the known state after a sequence: the search
    stopped there. ``findings``: those kept until then; ``after``: the sequence that
    left the unit so (empty: the first known state)."""

    def __init__(self, why: str, findings: list[Finding], after: list[Step]) -> None:
        super().__init__(why)
        self.findings = findings
        self.after = after


def search(pair: Pair, options: Options, budget: Budget, *, seed: int = 0,
           stop_after: int | None = None, with_probes: bool = True,
           on_finding: Callable[[Finding], None] | None = None,
           on_seen: Callable[[Finding], None] | None = None,
           on_dropped: Callable[[Finding], None] | None = None,
           reach: Reach | None = None) -> list[Finding]:
    """Disagreements between the pair's sides, each shrunk and kept once (by its rule
    and kind), until the budget is spent (or ``stop_after`` findings): first the probes
    and the tables' sweep (unless ``with_probes`` is false), each run whole, then the
    sequences Hypothesis draws. ``on_seen`` is told of a disagreement as soon as it is
    seen (before it is shrunk), ``on_finding`` once it is kept, ``on_dropped`` when one
    seen is not (the same as one kept, or not seen again in real time); ``reach`` counts
    what the sequences reached. ``--seconds`` holds everywhere: no sequence, step or
    shrink begins once the time is up. :class:`KnownStateLost` (with the findings kept)
    when the target could not be brought to the known state: never a search that ended."""
    hunt = _Search(pair, budget, stop_after, on_finding, on_seen, on_dropped)
    pair.out_of_time, pair.reach = budget.out_of_time, reach
    try:
        found = _hunt(hunt, pair, options, budget, seed, with_probes)
    finally:
        pair.out_of_time, pair.reach = _never, None
    if pair.lost:
        raise KnownStateLost(pair.lost, found, pair.led_there)
    return found


def _hunt(hunt: _Search, pair: Pair, options: Options, budget: Budget, seed: int,
          with_probes: bool) -> list[Finding]:
    grammar = Grammar(pair.profile, options)
    # the probes, then every table value once (the tables' sweep), then the matrix's cells
    matrix = cells(pair.profile, options) if with_probes else []
    runnable = [c for c in matrix if not c.left_out]
    written = ([steps for _, steps in grammar.probes()] + grammar.sweep()) if with_probes \
        else []
    ran: list[Cell] = []
    for steps, cell in [(s, None) for s in written] + [(list(c.steps), c) for c in runnable]:
        if not hunt.more():
            break
        found = hunt.trial(steps)
        if cell is not None:
            ran.append(cell)
        if found is not None:
            hunt.keep(found, written=True)
    if pair.reach is not None and matrix:
        pair.reach.matrix(matrix, ran)
    if not hunt.more():
        return hunt.findings
    strategy = grammar.sequences()
    rounds = 0
    while hunt.more():
        skipped = hunt.skipped
        found = hunt.draw(strategy, seed + rounds)
        rounds += 1
        if found is None:
            if budget.spent() or (budget.examples is not None and hunt.skipped == skipped):
                break                  # (with examples left: Hypothesis found nothing new)
            continue
        hunt.keep(found)
    return hunt.findings


def _never() -> bool:
    return False
