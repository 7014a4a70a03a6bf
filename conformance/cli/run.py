"""The default job of `gve-conformance`: run the suite, print verdicts, write reports.

With no arguments: the whole suite against the embedded emulator, every profile.
Everything a user can get wrong is refused before the first frame is sent, with one
line on standard error and exit status 2.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
import uuid
from pathlib import Path
from typing import NoReturn

from conformance.catalogue import select
from conformance.reports import write_reports
from conformance.runner import CaseResult, RunResult, run
from conformance.settings import PROFILES
from conformance.targets import DEFAULT_MAX_TRAVEL, Target, parse_target
from conformance.verdict import ORDER, PASS, failing
from gve_fixtures.profile import available_profiles

PROG = "gve-conformance"


class UsageError(Exception):
    """A mistake on the command line: one line, exit status 2, nothing sent."""


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> NoReturn:
        raise UsageError(message)


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    ap = _Parser(prog=PROG, description=__doc__.splitlines()[0])
    ap.add_argument("--target", action="append", default=[],
                    help="emu:PROFILE (default: every profile), serial:/dev/X?baud=&address=, "
                         "tcp:HOST:PORT; repeatable")
    ap.add_argument("--profile", help="the behaviour expected of a serial/tcp target "
                                      "(with no --target: run the emulator as this profile)")
    ap.add_argument("--cases", action="append", default=[], metavar="GLOB",
                    help="run only cases whose ID matches (repeatable)")
    ap.add_argument("--exclude", action="append", default=[], metavar="GLOB")
    ap.add_argument("--settings", default=None, choices=sorted(PROFILES),
                    help="Hypothesis settings profile (default: ci on the emulator, "
                         "hardware on serial/tcp targets)")
    ap.add_argument("--max-travel", type=int, default=DEFAULT_MAX_TRAVEL,
                    help="real units: the motion envelope in full steps per axis either side "
                         "of where the run began (default %(default)s)")
    ap.add_argument("--allow-destructive", action="store_true",
                    help="real units: allow J, W and EEPROM writes (EEPROM backed up and "
                         "restored)")
    ap.add_argument("--mutant", help="emulator targets: plant this deliberate bug")
    ap.add_argument("--report-dir", default="reports", help="where reports/<run id>/ go")
    ap.add_argument("--no-reports", action="store_true")
    ap.add_argument("--list", action="store_true", help="list the cases and exit")
    ap.add_argument("--coverage", nargs="?", const="unit", choices=("unit", "host"),
                    help="print which rules of the spec the (selected) cases can fail, per "
                         "section and profile, and the rules without one; exit 0")
    ap.add_argument("-q", "--quiet", action="store_true", help="print only what is not PASS")
    return ap.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    try:
        return _main(argv)
    except UsageError as err:
        print(f"{PROG}: {err}", file=sys.stderr)
        return 2
    except BrokenPipeError:
        _quiet_stdout()          # `gve-conformance --list | head -1`: end quietly
        return 0


def _quiet_stdout() -> None:
    """Standard output was closed by the reader: send the rest nowhere."""
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, sys.stdout.fileno())


def _say(text: str = "") -> None:
    """A console line; a closed standard output does not stop a run on a real unit."""
    try:
        print(text, flush=True)
    except BrokenPipeError:
        _quiet_stdout()


def _main(argv: list[str] | None) -> int:
    args = parse_args(argv)
    cases = select(args.cases or None, args.exclude or None)
    if not cases:
        raise UsageError("no case matches " + " ".join(
            [f"--cases {g!r}" for g in args.cases] + [f"--exclude {g!r}" for g in args.exclude]))
    if args.list:
        for c in cases:
            print(f"{c.id:48} {c.tag:6} {c.rule}")
        return 0
    if args.coverage:
        from conformance.coverage import coverage, format_coverage
        profiles = [args.profile] if args.profile else None
        try:
            report = coverage(profiles, role=args.coverage, cases=cases)
        except LookupError as err:
            raise UsageError(str(err).strip("'\"")) from None
        print(format_coverage(report, args.coverage))
        return 0
    targets = _targets(args)
    if not args.no_reports:
        _check_writable(Path(args.report_dir))
    _preflight(targets)
    run_id = time.strftime("%Y%m%d-%H%M%S") + "-" + uuid.uuid4().hex[:6]

    def show(r: CaseResult) -> None:
        if args.quiet and r.verdict == PASS:
            return
        line = f"{r.verdict:15} {r.id} [{r.profile}]"
        if r.failed_checks:
            c = r.failed_checks[0]
            line += f"  -- {c['what']}: observed {c['observed']!r}, expected {c['expected']!r}"
        elif r.verdict != PASS and r.notes:
            line += f"  -- {r.notes[0].splitlines()[0]}"
        _say(line)

    _say(f"Hypothesis settings: {_settings_line(targets, args.settings)}")
    result = run(targets, cases, settings_name=args.settings, run_id=run_id, on_result=show)
    counts = result.counts()
    summary = ", ".join(f"{v} {counts[v]}" for v in ORDER if v in counts)
    _say(f"\n{len(result.results)} case runs on {len(targets)} target(s): {summary}")
    _say(f"took {result.seconds:.1f} s, {result.frames} frames exchanged"
         f"{' (interrupted by Ctrl-C)' if result.interrupted else ''}")
    for line in _session_lines(result):
        _say(line)
    if not args.no_reports:
        folder = write_reports(result, args.report_dir)
        _say(f"reports: {folder}/junit.xml, results.json, report.html")
    bad = any(failing(r.verdict) for r in result.results)
    return 1 if bad or result.interrupted or result.problems else 0


def _targets(args: argparse.Namespace) -> list[Target]:
    every = [f"emu:{name}" for name in available_profiles()]
    if args.profile and not args.target:
        every = [f"emu:{args.profile}"]   # no target: the emulator behaving as --profile
    # no --target, or emu:all: the embedded emulator on every profile (--profile is for
    # the targets named)
    specs = [(s, t.split("?")[0] != "emu:all") for t in args.target or ["emu:all"]
             for s in (every if t.split("?")[0] == "emu:all" else [t])]
    try:
        return [parse_target(s, profile=args.profile if named else None,
                             allow_destructive=args.allow_destructive,
                             max_travel=args.max_travel, mutant=args.mutant)
                for s, named in specs]
    except (ValueError, LookupError) as err:
        raise UsageError(str(err).strip("'\"")) from None


def _check_writable(folder: Path) -> None:
    try:
        folder.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=folder):
            pass
    except OSError as err:
        raise UsageError(f"cannot write reports to {folder}: {err.strerror or err}") from None


def _preflight(targets: list[Target]) -> None:
    for target in targets:
        try:
            target.preflight()
        except (ValueError, LookupError) as err:
            for t in targets:
                t.close()
            raise UsageError(str(err)) from None


def _settings_line(targets: list[Target], chosen: str | None) -> str:
    if chosen:
        return chosen
    kinds = {t.info.kind == "emu" for t in targets}
    parts = (["ci on the emulator"] if True in kinds else []) + \
        (["hardware on real units (no shrinking in real time)"] if False in kinds else [])
    return ", ".join(parts) + " (--settings to choose)"


def _session_lines(result: RunResult) -> list[str]:
    """Per real target: the largest excursion, what was restored, what could not be."""
    lines = []
    for spec, s in result.sessions.items():
        if not s["real"]:
            continue
        lines.append(f"{spec} ({s['profile']}"
                     + (f", {s['identity'].get('version')}" if s["identity"] else "") + "):")
        if s["excursion"]:
            axes = ", ".join(f"{a} {lo:+g}..{hi:+g}" for a, (lo, hi)
                             in zip(s["axes"], s["excursion"], strict=True))
            lines.append(f"  largest excursion (full steps, envelope ±{s['max_travel']}): {axes}")
        lines += [f"  restored: {r}" for r in s["restored"]]
        lines += [f"  reset: {r}" for r in s["reset"]]
    lines += [f"PROBLEM: {p}" for p in result.problems]
    return lines


if __name__ == "__main__":
    sys.exit(main())
