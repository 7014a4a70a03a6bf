"""Running cases against targets and collecting graded results: one
session per target per run, Ctrl-C, a target that stops answering."""

from __future__ import annotations

import re
import time
import traceback
from collections.abc import Callable
from dataclasses import asdict, dataclass, field

from conformance.case import settings as settings_profiles
from conformance.case.context import Case, CaseContext, CouldNotTest, Missing, SafetyStop
from conformance.link.framing import UnitDataError
from conformance.link.link import Link
from conformance.link.liveness import TargetNotResponding
from conformance.link.signals import StopSignals
from conformance.operator.console import Console
from conformance.operator.hands import HandRig, Hands, cannot_by_hand
from conformance.run.metadata import RunMeta
from conformance.targets import Session, SessionError, Target
from conformance.verdicts.check import Check
from conformance.verdicts.verdict import (
    ALWAYS,
    COULD_NOT_TEST,
    ERROR,
    FAIL,
    MISSING,
    PASS,
    SILENT,
    UNREADABLE,
    grade,
    worst,
)
from gve_fixtures.rules import load_rules


@dataclass
class CaseResult:
    id: str
    section: str
    rule: str
    tag: str
    source: str
    profile: str
    target: str
    verdict: str
    checks: list[dict] = field(default_factory=list)     # each a Check.to_dict()
    notes: list[str] = field(default_factory=list)
    wire_log: list[str] = field(default_factory=list)
    artifacts: dict[str, str] = field(default_factory=dict)
    traces: list[dict] = field(default_factory=list)      # CaseContext.trace
    seconds: float = 0.0
    frames: int = 0
    interrupted: bool = False       # Ctrl-C ended it
    stopped: str = ""               # why the rest of the run on this target did not run

    @property
    def failed_checks(self) -> list[dict]:
        return [c for c in self.checks if not c["ok"]]

    def to_dict(self) -> dict:
        return asdict(self)


@dataclass
class RunResult:
    run_id: str
    results: list[CaseResult] = field(default_factory=list)
    targets: list[str] = field(default_factory=list)
    settings: str = "ci"
    seconds: float = 0.0
    frames: int = 0
    interrupted: bool = False
    #: per target: its session's report (identity, envelope and largest excursion per
    #: axis, what was restored, what could not be) — SessionReport.to_dict()
    sessions: dict[str, dict] = field(default_factory=dict)
    #: what could not be restored or verified: the top of every report, exit status 1
    problems: list[str] = field(default_factory=list)
    meta: RunMeta = field(default_factory=RunMeta)

    def counts(self) -> dict[str, int]:
        out: dict[str, int] = {}
        for r in self.results:
            out[r.verdict] = out.get(r.verdict, 0) + 1
        return out


def settings_for(target: Target, chosen: str | None) -> str:
    """The Hypothesis settings on ``target``: as chosen, else `ci` in virtual time (the
    emulator, a co-simulator) and `hardware` on real units (no shrinking in real time)."""
    return chosen or ("ci" if target.info.virtual_time else "hardware")


def _result(case: Case, target: Target, verdict: str = PASS) -> CaseResult:
    return CaseResult(case.id, case.section, case.rule, case.tag, case.source,
                      target.profile.name, target.info.spec, verdict)


def run_case(case: Case, target: Target, settings_name: str | None = None,
             seed: int | None = None, console: Console | None = None) -> CaseResult:
    profile = target.profile
    result = _result(case, target)
    why = case.missing_for(profile)
    if why:
        result.verdict, result.notes = MISSING, [why]
        return result
    by_hand = case.rig and not target.info.has_rig
    if by_hand:
        why = _without_rig(case, console)
        if why:
            result.verdict, result.notes = COULD_NOT_TEST, [why]
            return result
    if case.destructive and not target.info.allow_destructive:
        result.verdict, result.notes = COULD_NOT_TEST, ["destructive: needs --allow-destructive"]
        return result
    session = target.session
    hand_rig = HandRig(lambda: ctx.link, console) if by_hand else None
    ctx = CaseContext(case, profile, target.info,
                      settings_profiles.get(settings_for(target, settings_name)),
                      _with_hands(session.open_link, hand_rig), seed=seed)
    ctx.operator = Hands(lambda: ctx.link, console)
    start = time.perf_counter()
    verdicts: list[str] = []
    ended = True
    try:
        case.func(ctx)
    except CouldNotTest as err:
        verdicts.append(COULD_NOT_TEST)
        ctx.note(f"could not test: {err}")
    except Missing as err:
        verdicts.append(MISSING)
        ctx.note(f"missing: {err}")
    except SafetyStop as err:
        verdicts.append(COULD_NOT_TEST)
        ctx.note(f"safety stop: {err}")
    except UnitDataError as err:
        ctx.expect(False, f"the unit's answer cannot be read: {err}", tag=ALWAYS,
                   rule=UNREADABLE, machinery=True)
    except KeyboardInterrupt:
        ended = False
        result.interrupted = True
        verdicts.append(COULD_NOT_TEST)
        ctx.note("interrupted by Ctrl-C: H and D sent, the rest of the run not run")
        if not session.interrupts.pending:
            session.interrupts.count += 1       # raised without the handler (e.g. a test)
        session.emergency_stop()
    except TargetNotResponding as err:
        ended = False
        result.stopped = str(err)
        ctx.expect(False, str(err), tag=ALWAYS, rule=SILENT, machinery=True)
    except SessionError as err:
        ended = False
        result.stopped = str(err)
        verdicts.append(COULD_NOT_TEST)
        ctx.note(f"could not test: {err}")
    except Exception:
        verdicts.append(ERROR)
        ctx.note("defect of the suite:\n" + traceback.format_exc())
    finally:
        for link in ctx.links:
            if ended:
                try:
                    link.settle(final=True)
                except TargetNotResponding as err:    # ended with the case: its failure
                    ended = False
                    result.stopped = str(err)
                    ctx.expect(False, str(err), tag=ALWAYS, rule=SILENT, machinery=True)
            for violation in link.violations:
                ctx.expect(False, violation.text, tag=ALWAYS if violation.always else None,
                           rule=violation.rule, machinery=True)
            for late in link.late:
                ctx.note(f"late answer (the spec sets no deadline): {late}")
        if ended and hand_rig is not None and ctx.links:
            _hands_off(hand_rig, ctx)
        if ended:
            _after_case(session, ctx)
    result.seconds = time.perf_counter() - start
    verdicts += [grade(c.tag, target.info.strict) for c in ctx.checks if not c.ok]
    if not verdicts and not ctx.checks:
        verdicts.append(ERROR)
        ctx.note("the case recorded no check: a case that cannot fail is a defect")
    result.verdict = worst(verdicts)
    result.checks = [c.to_dict() for c in ctx.checks]
    result.notes = ctx.notes
    result.artifacts, result.traces = ctx.artifacts, ctx.traces
    result.wire_log = [line for link in ctx.links for line in
                       ["# link", *link.transcript_lines()]]
    result.frames = sum(link.frames for link in ctx.links)
    return result


def step_results(session: Session, target: Target) -> list[CaseResult]:
    """The known-state steps that failed since the last call (targets/session.py
    :class:`StepFailure`), each a result of its own: a FAIL of the step's rule (graded by
    its tag), filed under the rule's section as ``<section>.known-state.<step>``."""
    out = []
    for f in session.take_failures():
        rule = load_rules()[f.rule]
        section = re.match(r"\d+(?:\.\d+)*", f.rule).group(0)   # as a case's ID files it
        r = CaseResult(f"{section}.known-state.{f.step}", section, rule.text,
                       rule.tag, rule.source, target.profile.name, target.info.spec,
                       grade(rule.tag, target.info.strict))
        r.checks = [Check(False, f.what, f.observed, f.expected, rule.tag, f.rule).to_dict()]
        r.notes = ["a step of the known state the suite sets before each case relies on "
                   "this rule of the manual and the unit broke it; the run went on where "
                   "it safely could"]
        r.wire_log = list(f.led_there)
        out.append(r)
    return out


def _without_rig(case: Case, console: Console | None) -> str | None:
    """Why the rig case cannot run on a target without a rig (None: the technician's
    hands stand in for it)."""
    cannot = cannot_by_hand(case.id)
    if cannot:
        return f"needs a test rig: no hand can do it: {cannot}"
    if console is None or not console.interactive:
        return ("needs a test rig (the emulator's, or an exec: simulator's control channel) "
                "or a technician's hands: run gve-conformance on a terminal with --operator")
    return None


def _with_hands(open_link: Callable[..., Link], hands: HandRig | None) -> Callable[..., Link]:
    """``open_link``, its links' rig the technician's hands when ``hands`` is given."""
    if hands is None:
        return open_link

    def opened(*args: object, **kwargs: object) -> Link:
        link = open_link(*args, **kwargs)
        link.rig = hands
        return link
    return opened


def _hands_off(hands: HandRig, ctx: CaseContext) -> None:
    """The inputs the technician changed, put back as found (a step skipped here is
    noted: the next cases find the input as it was left)."""
    try:
        hands.hands_off()
    except (CouldNotTest, SafetyStop, TargetNotResponding, KeyboardInterrupt) as err:
        ctx.note(f"after the case, the hands stayed on: {err}")


def _after_case(session: Session, ctx: CaseContext) -> None:
    """The session's clean-up after a case (EEPROM bytes it wrote put back)."""
    try:
        session.after_case()
    except (KeyboardInterrupt, TargetNotResponding, SafetyStop) as err:
        ctx.note(f"after the case: {type(err).__name__} {err}")


def run(targets: list[Target], cases: list[Case], *, settings_name: str | None = None,
        run_id: str = "", on_result: Callable[[CaseResult], None] | None = None,
        seed: int | None = None, console: Console | None = None) -> RunResult:
    """Every case on every target, one session per target; Ctrl-C stops the run after
    `H` and `D` and the restorations (docs/suite.md)."""
    chosen = sorted({settings_for(t, settings_name) for t in targets})
    run = RunResult(run_id, targets=[t.info.spec for t in targets],
                    settings=", ".join(chosen) or (settings_name or "ci"))
    interrupts = StopSignals()
    start = time.perf_counter()

    def add(r: CaseResult) -> None:
        run.results.append(r)
        run.frames += r.frames
        if on_result:
            on_result(r)

    with interrupts.catching():
        for target in targets:
            if interrupts.stopped:
                break
            _run_target(target, cases, interrupts, settings_for(target, settings_name), add, run,
                        seed, console)
    run.interrupted = interrupts.stopped
    run.seconds = time.perf_counter() - start
    return run


def _run_target(target: Target, cases: list[Case], interrupts: StopSignals, settings: str,
                add: Callable[[CaseResult], None], run: RunResult, seed: int | None,
                console: Console | None) -> None:
    session = target.begin(interrupts)
    stopped = ""
    try:
        try:
            session.start()
        except (SessionError, TargetNotResponding) as err:
            stopped = str(err)
            if cases and isinstance(err, TargetNotResponding):
                first = _result(cases[0], target, FAIL)
                first.checks = [Check(False, stopped, tag=ALWAYS, rule=SILENT).to_dict()]
                first.stopped = stopped
                add(first)
                cases = cases[1:]
        except KeyboardInterrupt:
            session.emergency_stop()
            return
        for case in cases:
            if stopped or interrupts.stopped:
                if stopped:
                    r = _result(case, target, COULD_NOT_TEST)
                    r.notes = [f"not run: {stopped}"]
                    add(r)
                continue
            r = run_case(case, target, settings, seed, console)
            add(r)
            for step in step_results(session, target):
                add(step)
            stopped = r.stopped
    finally:
        try:
            report = session.finish()
        except KeyboardInterrupt:
            report = session.report
            report.problems.append("restorations abandoned (Ctrl-C pressed three times)")
        for step in step_results(session, target):
            add(step)
        run.sessions[target.info.spec] = report.to_dict()
        run.problems += report.problems
        target.close()
