"""The default job of `gve-conformance`: run the suite, show progress, write reports.

With no arguments: the whole suite against the embedded emulator, every profile.
"""

from __future__ import annotations

import argparse
import sys
import time
import uuid
from contextlib import ExitStack
from pathlib import Path

from serial import SerialException

from conformance.catalogue import select
from conformance.cli.progress import Progress
from conformance.cli.unit import confirmed, record_identities, resolve
from conformance.coverage import coverage, format_coverage
from conformance.metadata import RunMeta, now_iso
from conformance.operator import Console
from conformance.reports import write_junit, write_reports
from conformance.runner import run
from conformance.settings import DEFAULT_DATABASE, PROFILES, example_database, run_seed
from conformance.targets import DEFAULT_MAX_TRAVEL, Target, parse_target
from conformance.verdict import FAILED, ORDER, overall
from gve_fixtures.profile import available_profiles


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    ap = argparse.ArgumentParser(prog="gve-conformance", description=__doc__.splitlines()[0])
    ap.add_argument("--target", action="append", default=[],
                    help="emu:PROFILE (default: every profile), serial:/dev/X?baud=&address=, "
                         "tcp:HOST:PORT; repeatable")
    ap.add_argument("--profile", help="the behaviour expected of a serial/tcp target; 'auto': "
                    "ask the unit (? and Q) and choose")
    ap.add_argument("--variant", help="with --profile auto, where the unit's answer does not "
                    "say it: the variant (e.g. 100 for a GVE84-100)")
    ap.add_argument("--yes", action="store_true",
                    help="real units: move without asking first (unattended benches)")
    ap.add_argument("--operator", action=argparse.BooleanOptionalAction, default=None,
                    help="real units: ask a technician for hand steps (ground an input...); "
                         "default: when standard input is a terminal")
    ap.add_argument("--cases", action="append", default=[], metavar="GLOB",
                    help="run only cases whose ID matches (repeatable)")
    ap.add_argument("--exclude", action="append", default=[], metavar="GLOB")
    ap.add_argument("--settings", default="ci", choices=sorted(PROFILES),
                    help="Hypothesis settings profile (default ci)")
    ap.add_argument("--seed", type=int, metavar="N",
                    help="the Hypothesis machines' seed: the same N replays the same examples "
                         "(default: a fresh one, printed; none for derandomized settings)")
    ap.add_argument("--max-travel", type=int, default=DEFAULT_MAX_TRAVEL,
                    help="real units: the motion envelope in steps per axis")
    ap.add_argument("--allow-destructive", action="store_true",
                    help="real units: allow J and EEPROM writes (backed up and restored)")
    ap.add_argument("--mutant", help="emulator targets: plant this deliberate bug")
    ap.add_argument("--report-dir", default="reports", help="where reports/<run id>/ go")
    ap.add_argument("--run-id", metavar="NAME",
                    help="the report folder's name (default: date, time and a random tag)")
    ap.add_argument("--jobs", "-j", type=int, default=1, metavar="N",
                    help="run the targets in N parallel processes: one report per target "
                         "under reports/<run id>/ and a summary across them")
    ap.add_argument("--hypothesis-db", metavar="DIR|redis://HOST:PORT/N|none",
                    help="where the machines keep failing examples, tried first by the next "
                         "run (redis: by every bench sharing it); default: "
                         f"REPORT_DIR/{DEFAULT_DATABASE}, none with --no-reports")
    ap.add_argument("--no-reports", action="store_true")
    ap.add_argument("--junitxml", metavar="PATH", help="also write the JUnit XML at PATH")
    ap.add_argument("--full-logs", action="store_true",
                    help="whole wire logs in the reports for passing cases too")
    ap.add_argument("--operator-name", default="", metavar="NAME",
                    help="who ran the suite, for the report")
    ap.add_argument("--list", action="store_true", help="list the cases and exit")
    ap.add_argument("--coverage", nargs="?", const="unit", choices=("unit", "host"),
                    help="print which rules of the spec the (selected) cases can fail, per "
                         "section and profile, and the rules without one; exit 0")
    ap.add_argument("-q", "--quiet", action="store_true", help="print only what is not PASS")
    return ap.parse_args(argv)


class Refused(Exception):
    """The run cannot start; the message says why (exit status 2)."""


def _meta(args: argparse.Namespace, argv: list[str], targets: list[Target], cases: list,
          seed: int | None) -> RunMeta:
    meta = RunMeta(started=now_iso(), operator=args.operator_name, command=argv,
                   settings=args.settings, seed=seed, mutant=args.mutant,
                   destructive=args.allow_destructive, max_travel=args.max_travel,
                   cases=args.cases, exclude=args.exclude, full_logs=args.full_logs)
    for target in targets:
        t = meta.target(target.info.spec)
        t.kind, t.profile = target.info.kind, target.profile.name
        t.envelope = None if target.info.kind == "emu" else target.info.max_travel
    meta.coverage = [{**d, "sections": [{**s, "covered": len(s["covered"])}
                                        for s in d["sections"]]}
                     for d in (pc.as_dict() for pc in coverage(
                         sorted({t.profile.name for t in targets}), cases=cases))]
    return meta


def prepare(args: argparse.Namespace, argv: list[str], cases: list, console: Console
            ) -> tuple[list[Target], RunMeta]:
    """The targets and the run's metadata: profiles chosen (``--profile auto`` asks the
    units), identities recorded, motion confirmed on real units. Refused when not."""
    every = [f"emu:{name}" for name in available_profiles()]
    # no --target, or emu:all: the embedded emulator on every profile
    specs = [s for t in args.target or ["emu:all"]
             for s in (every if t.split("?")[0] == "emu:all" else [t])]
    try:
        chosen = [resolve(s, args.profile, args.variant, console) for s in specs]
        targets = [parse_target(s, profile=p, allow_destructive=args.allow_destructive,
                                max_travel=args.max_travel, mutant=args.mutant)
                   for s, p, _ in chosen]
        meta = _meta(args, argv, targets, cases, run_seed(args.settings, args.seed))
        record_identities(targets, meta)
    except (ValueError, LookupError, OSError, SerialException) as err:
        raise Refused(str(err)) from err
    for (_, _, how), target in zip(chosen, targets, strict=True):
        meta.target(target.info.spec).profile_chosen = how
    real = any(t.info.kind != "emu" for t in targets)
    meta.operator_steps = (real and console.interactive if args.operator is None
                           else args.operator)
    if real:
        meta.confirmed = "--yes" if args.yes else "asked"
        if not args.yes and not confirmed(targets, meta, console):
            raise Refused("motion not confirmed, nothing that moves was sent (answer y, or "
                          "give --yes on an unattended bench)")
    return targets, meta


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    return execute(parse_args(argv), argv)


def example_database_of(args: argparse.Namespace) -> str | None:
    """Where the run keeps failing examples (docs/ci.md): --hypothesis-db, else a folder
    beside the reports (nowhere when the run writes no reports)."""
    if args.hypothesis_db is not None:
        return args.hypothesis_db
    return None if args.no_reports else str(Path(args.report_dir, DEFAULT_DATABASE))


def execute(args: argparse.Namespace, argv: list[str]) -> int:
    """The run that ``argv`` (parsed as ``args``) asks for; also what each process of a
    fleet runs for its one target."""
    cases = select(args.cases or None, args.exclude or None)
    if args.list:
        for c in cases:
            print(f"{c.id:48} {c.tag:6} {c.rule}")
        return 0
    if args.coverage:
        profiles = [args.profile] if args.profile else None
        try:
            report = coverage(profiles, role=args.coverage, cases=cases)
        except LookupError as err:
            print(f"gve-conformance: {err}", file=sys.stderr)
            return 2
        print(format_coverage(report, args.coverage))
        return 0
    if args.jobs < 1:
        print("gve-conformance: --jobs must be 1 or more", file=sys.stderr)
        return 2
    database = example_database_of(args)
    with ExitStack() as run_scope:
        try:
            run_scope.enter_context(example_database(database))
        except ValueError as err:
            print(f"gve-conformance: --hypothesis-db: {err}", file=sys.stderr)
            return 2
        console = Console()
        try:
            targets, meta = prepare(args, argv, cases, console)
        except Refused as err:
            print(f"gve-conformance: {err}", file=sys.stderr)
            return 2
        except KeyboardInterrupt:
            print("\ngve-conformance: interrupted before the run, nothing that moves was sent",
                  file=sys.stderr)
            return 130
        run_id = args.run_id or time.strftime("%Y%m%d-%H%M%S") + "-" + uuid.uuid4().hex[:6]
        if args.jobs > 1 and len(targets) > 1:
            from conformance.cli.fleet import run_fleet
            for target in targets:
                target.close()          # each member opens its own port
            return run_fleet(args, argv, targets, run_id, meta.seed, database)
        return _run(args, targets, cases, meta, console, run_id)


def _run(args: argparse.Namespace, targets: list[Target], cases: list, meta: RunMeta,
         console: Console, run_id: str) -> int:
    seed = meta.seed
    print(f"seed {seed} (the same examples again: --seed {seed})" if seed is not None else
          f"seed: none (--settings {args.settings} is derandomized: every run draws the same "
          "examples; --seed N for others)", flush=True)
    progress = Progress(len(targets) * len(cases), quiet=args.quiet)
    try:
        result = run(targets, cases, settings_name=args.settings, run_id=run_id,
                     on_result=progress.result, seed=seed,
                     console=console if meta.operator_steps else None)
    finally:
        progress.close()
    meta.finished = now_iso()
    result.meta = meta
    counts = result.counts()
    summary = ", ".join(f"{v} {counts[v]}" for v in ORDER if v in counts)
    verdict, reason = overall([r.verdict for r in result.results], result.interrupted)
    print(f"\n{len(result.results)} case runs on {len(targets)} target(s): {summary}")
    print(f"took {result.seconds:.1f} s, {result.frames} frames exchanged"
          f"{' (interrupted by Ctrl-C)' if result.interrupted else ''}")
    if not args.no_reports:
        folder = write_reports(result, args.report_dir)
        print(f"reports: {folder}/report.html, results.json, junit.xml")
    if args.junitxml:
        print(f"JUnit XML: {write_junit(result, args.junitxml)}")
    print(f"{verdict}: {reason}")
    return 1 if verdict == FAILED else 0


if __name__ == "__main__":
    sys.exit(main())
