"""Grading one scenario: the host rules found on the wire, and the
executed motion against the clean run's.

- On the clean line the host must finish its own job (exit 0): a host that cannot is a
  FAIL whatever the tag, as a crash is (spec preamble).
- Under a fault every vector runs exactly once, in order, under the settings of the clean
  run, and the motion ends where it ended there (8.recovery.exactly-once): a host that
  exits 0 while the motion differs corrupted the work silently; a vector run twice or
  lost is a FAIL whatever the exit.
- A host that gives up honestly (exits non-zero, the motion a beginning of the job's) did
  not recover as spec 8 allows (8.recovery.finishes, NON-STRICT); one that neither
  finishes nor gives up hangs: a FAIL whatever the tag.
- The interrupt scenario also asks that the host noticed INTA (4.response.inta-bit); giving
  up there is a fair answer. The restart scenario is INFO: every finding is reported,
  none is held against the host.
"""

from __future__ import annotations

import difflib
from collections.abc import Callable
from dataclasses import dataclass, field

from conformance.host.checks import WIRE_CHECKS, Judgement, findings_by_rule
from conformance.host.final_state import Final
from conformance.host.line_faults import Fault
from conformance.host.recording import Recording
from conformance.host.scenarios import Baseline, Scenario
from conformance.host.unitview import VECTORS, Executed, UnitView
from conformance.protocol.catalogue import classes
from conformance.run.coverage import register_host_check
from conformance.run.runner import CaseResult
from conformance.verdicts.check import Check
from conformance.verdicts.verdict import COULD_NOT_TEST, PASS, grade, worst
from gve_fixtures.rules import load_rules

NS = 1e9
#: commands by which a host shows it noticed an interrupt (spec 10.4, 10.5)
REACTIONS = classes(reaction=True)


@dataclass
class HostResult(CaseResult):
    """A scenario's result: a CaseResult (reports read it as any case's) with the host
    run's own figures."""

    scenario: str = ""
    fault: str = ""
    injected: bool = False
    exit_code: int | None = None
    ended: str = ""                    # exited, silent (a hang), limit, operator
    rules_judged: list[str] = field(default_factory=list)


@dataclass
class HostRun:
    """What one run of the host under one fault left behind."""

    recording: Recording
    views: list[UnitView]
    finals: dict[int, Final]
    exit_code: int | None
    ended: str
    seconds: float
    fault: Fault
    output: str = ""


def executed(views: list[UnitView]) -> dict[int, list[Executed]]:
    return {v.address: list(v.executed) for v in views}


def difference(expected: list[Executed], got: list[Executed]) -> str | None:
    """None when the two runs executed the same; else the first difference, in words."""
    matcher = difflib.SequenceMatcher(a=expected, b=got, autojunk=False)
    for op, i1, _, j1, _ in matcher.get_opcodes():
        if op == "equal":
            continue
        if op == "delete":
            return f"{_short(expected[i1])} (step {i1 + 1} of the job) never ran"
        if op == "insert":
            again = got[j1] in expected[:i1]
            return (f"{_short(got[j1])} ran twice" if again else
                    f"{_short(got[j1])} ran, which the clean run never did")
        e, g = expected[i1], got[j1]
        if (e.kind, e.values) == (g.kind, g.values):
            diff = ", ".join(f"{k}{dict(g.modal).get(k)} instead of {k}{v}"
                             for k, v in e.modal if dict(g.modal).get(k) != v)
            return f"step {i1 + 1}, {_short(e)}, ran with {diff}"
        return f"step {i1 + 1}: {_short(g)} ran instead of {_short(e)}"
    return None


def _short(step: Executed) -> str:
    return f"`{step.kind}{','.join(map(str, step.values))}`"


class Grader:
    """Collects a scenario's checks, each naming its rule, and grades them."""

    def __init__(self, scenario: Scenario, strict: bool) -> None:
        self.scenario, self.strict = scenario, strict
        self.checks: list[Check] = []
        self.floor: list[str] = []
        self.notes: list[str] = []

    def check(self, ok: bool, rule: str, what: str, observed: str = "",
              tag: str | None = None) -> None:
        tag = tag or load_rules()[rule].tag
        if self.scenario.info and tag != "D-info":
            tag = "D-info"
        # the rule's ID leads the text, so that every report shows it
        self.checks.append(Check(ok, f"{rule}: {what}", observed, load_rules()[rule].text,
                                 tag, rule))

    def verdict(self) -> str:
        failed = [grade(c.tag, self.strict) for c in self.checks if not c.ok]
        return worst(failed + self.floor) if failed or self.floor else PASS


def wire_checks(g: Grader, j: Judgement) -> None:
    for rule, findings in findings_by_rule(j):
        tags = {f.tag for f in findings} or {None}
        for tag in sorted(tags, key=str):
            mine = [f for f in findings if f.tag == tag]
            if not mine:
                g.check(True, rule, "kept in every frame")
                continue
            first = mine[0]
            g.check(False, rule, first.what,
                    f"{len(mine)} time(s); first at {first.t / NS:.3f} s: {first.frame}",
                    tag)
    g.notes += j.notes


def travel(steps: list[Executed], axes: int) -> tuple[int, ...]:
    """The full steps each axis travelled in the executed vectors ``steps`` (the sum of
    their lengths, whatever the direction)."""
    out = [0] * axes
    for s in steps:
        if s.kind in VECTORS:
            for i, v in enumerate(s.values[:axes]):
                out[i] += abs(int(v))
    return tuple(out)


def driven_checks(g: Grader, out: HostRun, expect: dict[int, tuple[int, ...]] | None
                  ) -> None:
    """The clean run shows a host that drives its units: it sends frames, and the units
    execute the motion its job claims (``expect``: the travel per axis per address)."""
    n = len(out.recording.exchanges)
    g.check(n > 0, "2.link.host-drives", "the host sends its units frames on the clean "
            "line", f"{n} frame(s)", "always")
    for address, want in (expect or {}).items():
        view = next((v for v in out.views if v.address == address), None)
        axes = view.profile.axes if view is not None else ""
        got = travel(list(view.executed), len(axes)) if view is not None else ()
        want = tuple(want) + (0,) * (len(axes) - len(want))
        shown = ", ".join(f"{a} {s}" for a, s in zip(axes, got, strict=False))
        g.check(got == want, "2.link.host-drives", f"unit {address} executes the motion "
                "the job claims (--expect-motion "
                + ",".join(map(str, want)) + ")",
                f"it travelled {shown or 'nothing'} full steps", "always")


#: what a clean run that did not finish may owe to the unit played, not to the host
WRITTEN_FOR = ("a host written for a unit that reads a silence of the manuals otherwise "
               "than the unit played (docs/decisions.md) may fail here: play that "
               "reading with --reading NAME")


def motion_checks(g: Grader, out: HostRun, baseline: Baseline | None,
                  expect: dict[int, tuple[int, ...]] | None = None) -> None:
    sc = g.scenario
    finished = out.ended in ("exited", "operator") and out.exit_code == 0
    if sc.name == "clean":
        g.check(finished, "8.recovery.finishes", "the host finishes its own job on a "
                "clean line", _ending(out), "always")
        if not finished:
            g.notes.append(WRITTEN_FOR)
        driven_checks(g, out, expect)
        return
    hung = out.ended in ("silent", "limit")
    g.check(not hung, "8.recovery.finishes", "the host finishes or gives up after the "
            "fault; one that does neither hangs", _ending(out), "always")
    if baseline is None:
        g.floor.append(COULD_NOT_TEST)
        g.notes.append("no baseline: the host did not finish its job on the clean line")
        return
    got = executed(out.views)
    if sc.name == "restart":
        restart_checks(g, baseline, got)
        return
    for address, expected in baseline.executed.items():
        steps = got.get(address, [])
        if finished:
            why = difference(expected, steps) or _position(baseline, out, address)
            g.check(why is None, "8.recovery.exactly-once", "the host exited 0 and the "
                    "motion is the clean run's", why or "the same motion, the same end")
        else:
            prefix = steps == expected[: len(steps)]
            why = None if prefix else difference(expected[: len(steps)], steps)
            g.check(prefix, "8.recovery.exactly-once", "the motion before the host "
                    "stopped is the beginning of the clean run's", why or
                    f"{len(steps)} of {len(expected)} steps, in order")
    if not finished and not hung and sc.name != "interrupt":
        g.check(False, "8.recovery.finishes", "the host recovers (spec 8) and finishes "
                "its job", f"gave up: {_ending(out)}")


def restart_checks(g: Grader, baseline: Baseline, got: dict[int, list[Executed]]) -> None:
    """How the host took the restart (INFO): the motion before it, and none after it,
    as the unit's position was lost (spec 9: the counters start at 0)."""
    for address, expected in baseline.executed.items():
        steps = got.get(address, [])
        cut = next((i for i, s in enumerate(steps) if s.kind == "power-on"), len(steps))
        before, after = steps[:cut], [s for s in steps[cut + 1:] if s.kind in VECTORS]
        g.check(before == expected[: len(before)], "8.recovery.exactly-once",
                "the motion before the restart is the beginning of the clean run's",
                difference(expected[: len(before)], before) or f"{len(before)} steps")
        g.check(not after, "8.recovery.exactly-once", "no motion after the unit restarted "
                "(its position was lost)", f"{len(after)} vector(s) ran after the "
                "restart, the first " + _short(after[0]) if after else "none")


def _position(baseline: Baseline, out: HostRun, address: int) -> str | None:
    want, got = baseline.final.get(address), out.finals.get(address)
    if want is None or got is None or want.position == got.position:
        return (None if got is None or not got.stalled else
                f"the motion stalled: {got.note}")
    return f"the motion ended at {got.position}, the clean run's at {want.position}"


def _ending(out: HostRun) -> str:
    if out.ended == "silent":
        return f"silent for too long, not exited after {out.seconds:.1f} s"
    if out.ended == "limit":
        return (f"still running after {out.seconds:.1f} s (the clean run's limit is "
                "--clean-limit; a fault run's, twice the clean run's length)")
    return f"exit status {out.exit_code} after {out.seconds:.2f} s"


def interrupt_checks(g: Grader, rec: Recording) -> None:
    flagged = [i for i, ex in enumerate(rec.exchanges)
               if ex.delivered and ex.delivered[:1] in b"89ABCDEF"]
    if not flagged:
        g.notes.append("no answer carried INTA: the interrupt did not reach the host")
        return
    later = rec.exchanges[flagged[0] + 1:]
    noticed = any(ex.parsed.command in REACTIONS for ex in later)
    g.check(noticed, "4.response.inta-bit", "the host notices INTA in an answer",
            "it answered with " + ", ".join(sorted({ex.parsed.command or "?" for ex in later
                                                   if ex.parsed.command in REACTIONS}))
            if noticed else "it went on as if nothing had happened")


#: every rule a host certification can FAIL a host by -> the check that judges it: the
#: wire's (checks.py) and the executed motion's.
HOST_CHECKS: dict[str, Callable] = {
    **WIRE_CHECKS,
    "8.recovery.exactly-once": motion_checks,
    "8.recovery.finishes": motion_checks,
    "2.link.host-drives": driven_checks,
    "4.response.inta-bit": interrupt_checks,
}


def _register() -> None:
    """Tell coverage (``gve-conformance --coverage host``) which rules each check judges."""
    judged: dict[str, list[str]] = {}
    for rule, check in HOST_CHECKS.items():
        judged.setdefault(f"host.{check.__name__}", []).append(rule)
    for name, rules in judged.items():
        register_host_check(name, rules)


_register()


def result(g: Grader, out: HostRun, profile: str, target: str) -> HostResult:
    rec = out.recording
    sc = g.scenario
    if sc.name != "clean" and not out.fault.injected:
        g.floor.append(COULD_NOT_TEST)
        g.notes.append("the fault was never injected: the host's traffic differed from "
                       "the clean run's before its point")
    notes = [f"fault: {out.fault.describe()}", f"host: {_ending(out)}",
             *(f"{t / NS:.3f} s fault {what}" for t, what in
               ((t - rec.origin, what) for t, what in rec.faults)),
             *(f"unit {a}: {f.note}" for a, f in out.finals.items() if f.note), *g.notes]
    return HostResult(
        id=sc.id, section=sc.section, rule=sc.title, tag="D-info" if sc.info else "M",
        source="spec 2, 3, 6, 7, 8, 10.1", profile=profile, target=target,
        verdict=g.verdict(), checks=[c.to_dict() for c in g.checks], notes=notes,
        wire_log=rec.wire_log(), artifacts={"host output": out.output} if out.output else {},
        seconds=out.seconds, frames=len(rec.exchanges), scenario=sc.name,
        fault=out.fault.describe(), injected=out.fault.injected, exit_code=out.exit_code,
        ended=out.ended, rules_judged=sorted({c.rule for c in g.checks}))


def skipped(sc: Scenario, verdict: str, why: str, profile: str, target: str) -> HostResult:
    """A scenario that did not run: MISSING (the job has no point for it) or
    COULD-NOT-TEST."""
    return HostResult(id=sc.id, section=sc.section, rule=sc.title, tag="M",
                      source="spec 2, 3, 6, 7, 8, 10.1", profile=profile, target=target,
                      verdict=verdict, notes=[why], scenario=sc.name)
