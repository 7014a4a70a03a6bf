"""`gve-conformance fairness`: the fairness score — the whole catalogue and `diff` (its
probes and a bounded search) against the emulator taking each of its readings (the
other answers a careful reader of the manuals could give where they are silent;
emulator/readings.py), one at a time on one profile per family and all at once on
every profile, graded as any unit is (by the tags). A reading is fair when no case FAILs
or ERRs, diff finds no FAIL and runs to its end, and every difference either makes names
its rule; the score is fair readings / readings, and CI fails below 100 %.

A reading alone is tried on one profile per family among those the rules it reads apply
to (a packet's reading on the GVE84 and GVE114, which have packets): elsewhere it changes
nothing (:func:`trial_profiles`). diff runs on those profiles (all at once too: the
catalogue covers every profile), its budget its written sequences (probes, the tables'
sweep, the matrix's cells) and DIFF_DRAWN drawn ones from seed DIFF_SEED
(:func:`diff_budget`): the same sequences on every run, a few seconds a profile.

It ends as every gate does (cli/gate.py): the reports (a JUnit testcase per reading) and
one last line; ``--seconds`` bounds it, and a trial its time limit cut short ends
INCOMPLETE (exit status 3)."""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass, field

from conformance.cli.gate import Gate, GateItem, under_way
from conformance.cli.pool import workers
from conformance.cli.progress import HEARTBEAT, Progress
from conformance.cli.usage import (
    TIME_LIMIT_HELP,
    Parser,
    UsageError,
    chosen_cases,
    job_options,
    summary,
)
from conformance.link.framing import readable
from conformance.verdicts.verdict import ERROR, FAIL, INFO, NON_STRICT

PROG = "gve-conformance fairness"
#: one profile per family for the readings one at a time
FIRST = ("GVE84-100", "GVE54", "GVE114-500")
ALL = "all"
#: sequences diff draws after its probes on each profile, and the seed they come from
DIFF_DRAWN = 50
DIFF_SEED = 0


@dataclass
class Trial:
    """One reading (or ``all``) on its profiles: what it FAILed and what it changed."""

    reading: str
    profiles: list[str]
    unfair: list[str] = field(default_factory=list)       # FAIL, ERROR, an unnamed check
    differences: list[str] = field(default_factory=list)  # NON-STRICT, INFO with the rule
    diffs: list[str] = field(default_factory=list)        # what diff said, per profile
    seconds: float = 0.0

    @property
    def fair(self) -> bool:
        return not self.unfair


def trial(reading: str, readings: list[str], profiles: list[str],
          include: list[str] | None, exclude: list[str] | None = None) -> Trial:
    """Run the catalogue on ``profiles`` with the emulator taking ``readings``."""
    from conformance.run.runner import run_case
    from conformance.run.selection import select
    from conformance.targets import parse_target
    from conformance.verdicts.explain import reason
    result = Trial(reading, profiles)
    start = time.perf_counter()
    for p in profiles:
        target = parse_target(f"emu:{p}?reading={','.join(readings)}", allow_destructive=True)
        for c in select(include or None, exclude or None):
            r = run_case(c, target, "mutation")
            where = f"{c.id} [{p}]"
            failed = [ch for ch in r.checks if not ch["ok"]]
            unnamed = [ch for ch in r.checks if not ch.get("rule")]
            if unnamed:
                result.unfair.append(f"{r.verdict} {where}: a check names no rule: "
                                     f"{unnamed[0]['what']}")
            if r.verdict in (FAIL, ERROR):
                result.unfair.append(f"{r.verdict} {where}: {reason(r).line()[:300]}")
            elif r.verdict in (NON_STRICT, INFO):
                rules = sorted({ch["rule"] for ch in failed if ch.get("rule")})
                result.differences.append(f"{r.verdict} {where} ({', '.join(rules)})")
        if p in FIRST:
            diff_trial(p, readings, result)
    result.seconds = time.perf_counter() - start
    return result


def trial_profiles(rules: tuple[str, ...], profiles: list[str]) -> list[str]:
    """The ``profiles`` a reading of ``rules`` is tried on alone: those some rule of it
    applies to (the others meet none of what it reads)."""
    from gve_fixtures.profile import load_profile
    from gve_fixtures.rules import load_rules
    known = load_rules()
    return [p for p in profiles
            if any(known[r].applies_to(p, load_profile(p).family) for r in rules)]


def diff_budget(written: int) -> int:
    """Sequences diff runs on a profile: the written ones (its probes, the tables' sweep,
    the matrix's cells) and DIFF_DRAWN drawn ones."""
    return written + DIFF_DRAWN


def diff_trial(profile: str, readings: list[str], result: Trial) -> None:
    """`diff` of the emulator taking ``readings`` against the reference on ``profile``:
    the probes, then DIFF_DRAWN drawn sequences; its findings go to ``result``."""
    from conformance.diff.engine import Budget, Pair, search
    from conformance.diff.grammar import Grammar, Options
    from conformance.diff.matrix import cells
    from conformance.diff.sides import Side
    from conformance.link.liveness import TargetNotResponding
    from conformance.targets import SessionError, parse_target
    target = parse_target(f"emu:{profile}?reading={','.join(readings)}",
                          allow_destructive=True)
    reference = parse_target(f"emu:{profile}")
    options = Options(destructive=True, rig=target.info.has_rig and reference.info.has_rig)
    grammar = Grammar(target.profile, options)
    written = (len(grammar.probes()) + len(grammar.sweep())
               + sum(1 for c in cells(target.profile, options) if c.steps))
    budget = Budget(examples=diff_budget(written))
    pair = Pair(Side(target), Side(reference), target.profile)
    where = f"diff [{profile}]"
    try:
        findings = search(pair, options, budget, seed=DIFF_SEED)
    except (TargetNotResponding, SessionError) as err:
        result.unfair.append(f"{FAIL} {where}: stopped after {budget.used} sequences: {err}")
        result.diffs.append(f"{profile}: stopped after {budget.used} sequences")
        return
    said = []
    for f in findings:
        d = f.disagreement
        line = (f"{d.verdict} {where}: {d.rule or '(no known rule)'}: "
                f"{readable(d.target.sent)} target {readable(d.target.answer) or '(none)'}"
                f" / reference {readable(d.reference.answer) or '(none)'} ({d.kind})")
        if d.verdict in (FAIL, ERROR) or d.rule is None:
            result.unfair.append(line + ("" if d.rule else ": names no rule"))
        else:
            result.differences.append(line)
        said.append(f"{d.verdict} {d.rule or '(no known rule)'}")
    result.diffs.append(f"{profile}: {budget.used} sequences, "
                        + (", ".join(said) if said else "no difference"))


def _trial(args: tuple[str, list[str], list[str], list[str] | None, list[str] | None]
           ) -> Trial:
    return trial(*args)


def main(argv: list[str] | None = None) -> int:
    from conformance.targets.emu import emulator_readings
    from gve_fixtures.profile import available_profiles
    argv = sys.argv[1:] if argv is None else list(argv)
    ap = Parser(prog=PROG, description=summary(__doc__), examples=(
        "gve-conformance fairness --jobs 2",
        "gve-conformance fairness --reading NAME -v",
        "gve-conformance fairness --jobs 2 --seconds 900 --junitxml fairness.xml"),
        parents=[job_options("also list every difference each reading made", seed=None,
                             jobs="readings tried in parallel", cases=True,
                             time_limit=TIME_LIMIT_HELP)])
    ap.add_argument("--reading", action="append", default=[], metavar="NAME",
                    help="only this reading (repeatable; default: every one, and all at once)")
    try:
        args = ap.parse_args(argv)
        known = emulator_readings()
        wrong = [r for r in args.reading if r not in known]
        if wrong:
            raise UsageError(f"unknown reading(s) {', '.join(wrong)} "
                             f"(known: {', '.join(sorted(known))})")
        if args.cases or args.exclude:
            chosen_cases(args)
        gate = Gate("fairness", args, argv)
    except UsageError as err:
        print(f"{PROG}: {err}", file=sys.stderr)
        return 2
    names = args.reading or sorted(known)
    first = [p for p in FIRST if p in available_profiles()]
    chosen = (args.cases or None, args.exclude or None)
    jobs = [(n, [n], trial_profiles(known[n][0], first), *chosen) for n in names]
    if not args.reading:
        # all at once runs on every profile, the longest trial: first, so that the
        # workers do not wait for it at the end
        jobs.insert(0, (ALL, names, available_profiles(), *chosen))
    trials: list[Trial] = []
    with workers(args.jobs, args.seconds) as pool, Progress(
            len(jobs), unit="reading", quiet=args.quiet, verbose=args.verbose,
            every_step=True, heartbeat=HEARTBEAT) as shown:
        for t in pool.map(_trial, jobs):
            trials.append(t)
            shown.step("\n".join(_lines(t, args.verbose)), routine=t.fair)
    fair = sum(t.fair for t in trials)
    score = 100.0 * fair / len(trials) if trials else 100.0
    items = [GateItem(t.reading, t.fair, t.seconds, _lines(t, False)) for t in trials]
    return gate.end(
        items, [job[0] for job in jobs[len(trials):]], "reading",
        f"fairness score: {fair}/{len(trials)} = {score:.1f} % in "
        f"{time.perf_counter() - gate.start:.1f} s ({args.jobs} job(s)); "
        f"{sum(len(t.differences) for t in trials)} differences graded NON-STRICT or INFO",
        interrupted=pool.interrupted, timed_out=pool.timed_out, failed_word="unfair",
        under_way=under_way(args.jobs, len(jobs), len(trials)))


def _lines(t: Trial, verbose: bool) -> list[str]:
    """What a reading made: fair or not, what diff said, what was unfair (and with
    ``verbose`` every difference)."""
    head = "fair  " if t.fair else "UNFAIR"
    return [f"{head}  {t.reading:24} {len(t.differences)} difference(s) on "
            f"{', '.join(t.profiles) if t.reading != ALL else 'every profile'} "
            f"in {t.seconds:.1f} s",
            *(f"        diff {line}" for line in t.diffs),
            *(f"        {line}" for line in t.unfair),
            *(f"        {line}" for line in (t.differences if verbose else []))]


if __name__ == "__main__":
    sys.exit(main())
