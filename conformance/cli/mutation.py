"""`gve-conformance mutation`: the suite's mutation score. Every deliberate bug the
emulator can plant (its registry, through the ``emu`` target) is hunted with the case
catalogue until a case FAILs it; the command prints, per mutant, the case that caught it
and the time it took, then the score, and exits 1 below 100 % or when a case reported
ERROR on the way (a defect of the suite: a broken unit must make a case FAIL, never
crash it). ``--sweep`` runs the whole catalogue against every mutant on one profile per
family besides, for the ERRORs only a case that does not catch the mutant meets. The
sweep runs a case against a mutant only where the case's clean run reached the mutant's
code: elsewhere it runs exactly as on the clean unit, which is run once per case and
profile and reused for every mutant.

A mutant is stopped at its first FAIL by a case that PASSes the clean emulator on the
same profile (a case failing both proves nothing; it is reported). The cases of the
mutant's rule area (the spec section it breaks) run first, then the rest of the
catalogue; each on the profiles in turn (one per family first: a mutant of the GVE54's
micro-stepping shows only there). Hypothesis machines run with the ``mutation`` settings
(no shrinking).

It ends as every gate does (cli/gate.py): the reports (a JUnit testcase per mutant) and
one last line; ``--seconds`` bounds it, and a hunt its time limit cut short ends
INCOMPLETE (exit status 3).
"""

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
from conformance.verdicts.verdict import ERROR, FAIL
from gve_fixtures.rules import load_rules

PROG = "gve-conformance mutation"
#: profiles tried first, one per family; the others follow
FIRST = ("GVE84-100", "GVE114-500", "GVE54")


@dataclass
class Hunt:
    mutant: str
    area: str
    description: str
    caught_by: str | None = None     # "case [profile]"
    runs: int = 0                    # case runs it took
    unreached: int = 0               # case runs the sweep left out: the mutant's code unreached
    seconds: float = 0.0
    errors: list[str] = field(default_factory=list)   # suite defects met on the way
    clean_fails: list[str] = field(default_factory=list)   # cases failing the clean unit

    @property
    def caught(self) -> bool:
        return self.caught_by is not None


def profiles_in_order(chosen: list[str] | None = None) -> list[str]:
    from gve_fixtures.profile import available_profiles
    every = available_profiles()
    if chosen:
        return chosen
    return [p for p in FIRST if p in every] + [p for p in every if p not in FIRST]


def closeness(case, area: str) -> int:
    """How closely a case checks the rule area ``area`` (a spec section: 10 is the command
    table, 10.2 the motion model, each an area of its own): 0 filed there, 1 naming a rule
    of it, 2 neither."""
    if case.section == area:
        return 0
    rules = load_rules()
    return 1 if any(rules[r].section == area for r in case.rules) else 2


def hunt(mutant: str, profiles: list[str] | None = None,
         include: list[str] | None = None, sweep: bool = False,
         exclude: list[str] | None = None) -> Hunt:
    """Run cases against ``mutant`` until one FAILs (see the module's text); with
    ``sweep`` go on through the catalogue on one profile per family, noting ERRORs."""
    from conformance.run.runner import run_case
    from conformance.run.selection import select
    from conformance.targets import emu, parse_target
    area, description = emu.mutants()[mutant]
    result = Hunt(mutant, area, description)
    cases = select(include or None, exclude or None)
    ordered = sorted(cases, key=lambda c: closeness(c, area))      # stable: spec order
    area_cases = [c for c in ordered if closeness(c, area) < 2]
    names = profiles_in_order(profiles)
    targets = {p: (parse_target(f"emu:{p}", mutant=mutant), parse_target(f"emu:{p}"))
               for p in names}
    first = [p for p in names if p in FIRST] or names[:1]
    rest = [p for p in names if p not in first]
    # the area's cases on one profile per family, then the other cases there, then the
    # whole catalogue on the remaining profiles
    pairs = ([(c, p) for c in ordered[:len(area_cases)] for p in first]
             + [(c, p) for c in ordered[len(area_cases):] for p in first]
             + [(c, p) for c in ordered for p in rest])
    start = time.perf_counter()
    for c, p in pairs:
        target, clean = targets[p]
        if c.missing_for(target.profile) or (result.caught and p not in first):
            continue
        if sweep and mutant not in clean_run(c, clean)[1]:
            result.unreached += 1
            continue
        r = run_case(c, target, "mutation")
        result.runs += 1
        where = f"{c.id} [{p}]"
        if r.verdict == ERROR:
            result.errors.append(where)
        if r.verdict != FAIL or result.caught:
            continue
        if clean_run(c, clean)[0] in (FAIL, ERROR):
            result.clean_fails.append(where)
            continue
        result.caught_by = where
        result.seconds = time.perf_counter() - start
        if not sweep:
            return result
    result.seconds = time.perf_counter() - start
    return result


#: per case and clean target, in this process: its verdict and the mutants it reached
_CLEAN: dict[tuple[str, str], tuple[str, frozenset[str]]] = {}


def clean_run(case, clean) -> tuple[str, frozenset[str]]:
    """The verdict of ``case`` on the clean emulator ``clean`` and the mutants whose code
    it reached (run once per process: the runs are exact)."""
    from conformance.run.runner import run_case
    from conformance.targets.emu import mutants_reached
    key = (case.id, clean.info.spec)
    if key not in _CLEAN:
        with mutants_reached() as reached:
            verdict = run_case(case, clean, "mutation").verdict
        _CLEAN[key] = (verdict, frozenset(reached))
    return _CLEAN[key]


def _hunt(args: tuple[str, list[str] | None, list[str] | None, bool, list[str] | None]
          ) -> Hunt:
    return hunt(*args)


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    ap = Parser(prog=PROG, description=summary(__doc__), examples=(
        "gve-conformance mutation --jobs 2",
        "gve-conformance mutation --mutant NAME --profile GVE84-100",
        "gve-conformance mutation --sweep --jobs 2 --seconds 600 --junitxml mutation.xml"),
        parents=[job_options("print a line for every mutant on a terminal too (a log "
                             "always has them)", seed=None, jobs="mutants hunted in "
                             "parallel", cases=True, time_limit=TIME_LIMIT_HELP)])
    ap.add_argument("--profile", action="append", default=[],
                    help="hunt on this profile only (repeatable; default: every profile)")
    ap.add_argument("--mutant", action="append", default=[], metavar="NAME",
                    help="only this mutant (repeatable; default: every one)")
    ap.add_argument("--sweep", action="store_true",
                    help="also run the rest of the catalogue against each mutant (one "
                         "profile per family), failing on any ERROR")
    try:
        args = ap.parse_args(argv)
        from conformance.targets import emu
        from gve_fixtures.profile import available_profiles
        known = emu.mutants()
        wrong = [m for m in args.mutant if m not in known]
        wrong += [p for p in args.profile if p not in available_profiles()]
        if wrong:
            raise UsageError(f"unknown {', '.join(wrong)}")
        if args.cases or args.exclude:
            chosen_cases(args)
        gate = Gate("mutation", args, argv)
    except UsageError as err:
        print(f"{PROG}: {err}", file=sys.stderr)
        return 2
    names = args.mutant or sorted(known)
    jobs = [(m, args.profile or None, args.cases or None, args.sweep, args.exclude or None)
            for m in names]
    results: list[Hunt] = []
    with workers(args.jobs, args.seconds) as pool, Progress(
            len(jobs), unit="mutant", quiet=args.quiet, verbose=args.verbose,
            every_step=True, heartbeat=HEARTBEAT) as shown:
        for h in pool.map(_hunt, jobs):
            results.append(h)
            shown.step("\n".join(_lines(h)), routine=h.caught and not h.errors
                       and not h.clean_fails)
    caught = sum(h.caught for h in results)
    score = 100.0 * caught / len(results) if results else 100.0
    errors = sum(len(h.errors) for h in results)
    items = [GateItem(h.mutant, h.caught and not h.errors, h.seconds, _lines(h))
             for h in results]
    return gate.end(
        items, names[len(results):], "mutant",
        f"mutation score: {caught}/{len(results)} = {score:.1f} % in "
        f"{time.perf_counter() - gate.start:.1f} s ({args.jobs} job(s)); "
        f"{sum(h.runs for h in results)} case runs, {errors} ERROR"
        + (f"; {sum(h.unreached for h in results)} not run, the mutant's code unreached"
           if args.sweep else ""),
        interrupted=pool.interrupted, timed_out=pool.timed_out,
        under_way=under_way(args.jobs, len(jobs), len(results)))


def _runs(n: int) -> str:
    return f"{n} run" if n == 1 else f"{n} runs"


def _lines(h: Hunt) -> list[str]:
    """What a hunt found: caught (by what, how fast) or missed, and the ERRORs and
    clean-failing cases met on the way."""
    if h.caught:
        line = (f"caught  {h.mutant:32} by {h.caught_by} in {h.seconds:.2f} s "
                f"({_runs(h.runs)})")
    else:
        line = (f"MISSED  {h.mutant:32} ({h.area}: {h.description}) after {_runs(h.runs)} "
                f"in {h.seconds:.1f} s")
    return [line, *(f"        ERROR on the way (a defect of the suite): {e}" for e in h.errors),
            *(f"        not counted: {e} fails the clean emulator too" for e in h.clean_fails)]


if __name__ == "__main__":
    sys.exit(main())
