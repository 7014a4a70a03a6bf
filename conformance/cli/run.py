"""The default job of `gve-conformance`: run the suite, print verdicts, write reports.

With no arguments: the whole suite against the embedded emulator, every profile.
"""

from __future__ import annotations

import argparse
import sys

from conformance.catalogue import select
from conformance.cli.ending import counted, end, new_run_id, progress
from conformance.runner import CaseResult, run
from conformance.settings import PROFILES
from conformance.targets import DEFAULT_MAX_TRAVEL, parse_target
from gve_fixtures.profile import available_profiles


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    ap = argparse.ArgumentParser(prog="gve-conformance", description=__doc__.splitlines()[0])
    ap.add_argument("--target", action="append", default=[],
                    help="emu:PROFILE (default: every profile), serial:/dev/X?baud=&address=, "
                         "tcp:HOST:PORT; repeatable")
    ap.add_argument("--profile", help="the behaviour expected of a serial/tcp target")
    ap.add_argument("--cases", action="append", default=[], metavar="GLOB",
                    help="run only cases whose ID matches (repeatable)")
    ap.add_argument("--exclude", action="append", default=[], metavar="GLOB")
    ap.add_argument("--settings", default="ci", choices=sorted(PROFILES),
                    help="Hypothesis settings profile (default ci)")
    ap.add_argument("--max-travel", type=int, default=DEFAULT_MAX_TRAVEL,
                    help="real units: the motion envelope in steps per axis")
    ap.add_argument("--allow-destructive", action="store_true",
                    help="real units: allow J and EEPROM writes (backed up and restored)")
    ap.add_argument("--mutant", help="emulator targets: plant this deliberate bug")
    ap.add_argument("--report-dir", default="reports", help="where reports/<run id>/ go")
    ap.add_argument("--no-reports", action="store_true")
    ap.add_argument("--list", action="store_true", help="list the cases and exit")
    ap.add_argument("-q", "--quiet", action="store_true", help="print only what is not PASS")
    return ap.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    cases = select(args.cases or None, args.exclude or None)
    if args.list:
        for c in cases:
            print(f"{c.id:48} {c.tag:6} {c.rule}")
        return 0
    every = [f"emu:{name}" for name in available_profiles()]
    # no --target, or emu:all: the embedded emulator on every profile
    specs = [s for t in args.target or ["emu:all"]
             for s in (every if t.split("?")[0] == "emu:all" else [t])]
    try:
        targets = [parse_target(s, profile=args.profile, allow_destructive=args.allow_destructive,
                                max_travel=args.max_travel, mutant=args.mutant) for s in specs]
    except (ValueError, LookupError) as err:
        print(f"gve-conformance: {err}", file=sys.stderr)
        return 2

    def first_failed(r: CaseResult) -> str | None:
        c = r.failed_checks[0] if r.failed_checks else None
        return c and f"{c['what']}: observed {c['observed']!r}, expected {c['expected']!r}"

    result = run(targets, cases, settings_name=args.settings, run_id=new_run_id(),
                 on_result=progress(args.quiet, first_failed))
    print(f"\n{len(result.results)} case runs on {len(targets)} target(s): {counted(result)}")
    print(f"took {result.seconds:.1f} s, {result.frames} frames exchanged"
          f"{' (interrupted by Ctrl-C)' if result.interrupted else ''}")
    return end(result, None if args.no_reports else args.report_dir)


if __name__ == "__main__":
    sys.exit(main())
