"""Running cases against targets and collecting graded results (issue 4 items 1, 7)."""

from __future__ import annotations

import time
import traceback
from collections.abc import Callable
from dataclasses import asdict, dataclass, field

from conformance import settings as settings_profiles
from conformance.case import Case, CaseContext, CouldNotTest, Missing, SafetyStop
from conformance.metadata import RunMeta
from conformance.operator import Console, Hands
from conformance.targets import Target
from conformance.verdict import COULD_NOT_TEST, ERROR, MISSING, PASS, grade, worst


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
    checks: list[dict] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    wire_log: list[str] = field(default_factory=list)
    artifacts: dict[str, str] = field(default_factory=dict)
    traces: list[dict] = field(default_factory=list)      # CaseContext.trace
    seconds: float = 0.0
    frames: int = 0

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
    meta: RunMeta = field(default_factory=RunMeta)

    def counts(self) -> dict[str, int]:
        out: dict[str, int] = {}
        for r in self.results:
            out[r.verdict] = out.get(r.verdict, 0) + 1
        return out


def run_case(case: Case, target: Target, settings_name: str = "ci",
             seed: int | None = None, console: Console | None = None) -> CaseResult:
    profile = target.profile
    result = CaseResult(case.id, case.section, case.rule, case.tag, case.source,
                        profile.name, target.info.spec, PASS)
    why = case.missing_for(profile)
    if why:
        result.verdict, result.notes = MISSING, [why]
        return result
    if case.rig and not target.info.has_rig:
        result.verdict, result.notes = COULD_NOT_TEST, ["needs the emulator's test rig"]
        return result
    if case.destructive and not target.info.allow_destructive:
        result.verdict, result.notes = COULD_NOT_TEST, ["destructive: needs --allow-destructive"]
        return result
    ctx = CaseContext(case, profile, target.info, settings_profiles.get(settings_name),
                      target.open_link, seed=seed)
    ctx.operator = Hands(lambda: ctx.link, console)
    start = time.perf_counter()
    verdicts: list[str] = []
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
    except Exception:
        verdicts.append(ERROR)
        ctx.note("defect of the suite or the target's link:\n" + traceback.format_exc())
    finally:
        for link in ctx.links:
            if link.eeprom_backup:
                for problem in link.restore_eeprom():
                    ctx.expect(False, problem, tag="M")
    result.seconds = time.perf_counter() - start
    verdicts += [grade(c.tag, profile.implements_decisions) for c in ctx.checks if not c.ok]
    if not verdicts and not ctx.checks:
        verdicts.append(ERROR)
        ctx.note("the case recorded no check: a case that cannot fail is a defect")
    result.verdict = worst(verdicts)
    result.checks = [asdict(c) for c in ctx.checks]
    result.notes = ctx.notes
    result.artifacts, result.traces = ctx.artifacts, ctx.traces
    result.wire_log = [line for link in ctx.links for line in
                       ["# link", *link.transcript_lines()]]
    result.frames = sum(link.frames for link in ctx.links)
    return result


def run(targets: list[Target], cases: list[Case], *, settings_name: str = "ci",
        run_id: str = "", on_result: Callable[[CaseResult], None] | None = None,
        seed: int | None = None, console: Console | None = None) -> RunResult:
    run = RunResult(run_id, targets=[t.info.spec for t in targets], settings=settings_name)
    start = time.perf_counter()
    try:
        for target in targets:
            for case in cases:
                r = run_case(case, target, settings_name, seed, console)
                run.results.append(r)
                run.frames += r.frames
                if on_result:
                    on_result(r)
            target.close()
    except KeyboardInterrupt:
        run.interrupted = True
        for target in targets:
            if target.info.kind != "emu":
                target.emergency_stop()
            target.close()
    run.seconds = time.perf_counter() - start
    return run
