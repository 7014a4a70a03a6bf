"""The default job of `gve-conformance`: run the suite, show progress, write reports.

With no arguments: the whole suite against the embedded emulator, every profile.
Everything a user can get wrong is refused before the first frame is sent, with one
line on standard error and exit status 2.
"""

from __future__ import annotations

import argparse
import os
import sys
from contextlib import ExitStack
from pathlib import Path

from serial import SerialException

from conformance.case.settings import DEFAULT_DATABASE, PROFILES, example_database, run_seed
from conformance.cli.colour import wanted
from conformance.cli.commands import subcommands_help
from conformance.cli.ending import claimed, counted, end, new_run_id
from conformance.cli.preflight import (
    confirmed,
    consent,
    record_identities,
    resolve,
    unattended,
    unattended_specs,
)
from conformance.cli.progress import Progress
from conformance.cli.usage import (
    INTERRUPTED,
    Parser,
    UsageError,
    chosen_cases,
    job_options,
    positive,
    summary,
    writable_folder,
)
from conformance.link.account import account_lines
from conformance.operator.consent import ASKED
from conformance.operator.console import Console
from conformance.reports.files import release
from conformance.run.coverage import coverage, format_coverage
from conformance.run.metadata import RunMeta, now_iso
from conformance.run.runner import RunResult, run, settings_for
from conformance.targets import DEFAULT_MAX_TRAVEL, Target, parse_target
from conformance.verdicts.quoting import escaped
from gve_fixtures.profile import ProfileError, available_profiles

PROG = "gve-conformance"
#: what the run's --seed seeds
SEED_HELP = ("the Hypothesis machines' seed: the same N replays the same examples "
             "(default: a fresh one, printed and recorded; none for derandomized settings)")
ABOUT = ("The conformance and fuzz suite for GVE54, GVE84 and GVE114 serial motion "
         "controllers. With no subcommand (or with `run`) it runs the suite against the "
         "targets, shows its progress and writes the reports.")
EXAMPLES = (
    "gve-conformance                                   # every profile, embedded emulator",
    "gve-conformance --target serial:/dev/ttyUSB0?baud=115200 --profile auto",
    "gve-conformance --target tcp:127.0.0.1:5114 --profile GVE114-500 --yes",
    "gve-conformance --target 'exec:python -m emulator --model GVE84-100 --pty' "
    "--profile GVE84-100 --yes",
    "gve-conformance --target 'exec:python -m emulator --model GVE84-100 --cosim' "
    "--profile GVE84-100   # virtual time: nothing moves, no --yes",
    "gve-conformance --cases '6.*' -v                  # some cases, every line shown",
)


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    ap = Parser(prog=PROG, description=f"{summary(ABOUT)}\n\n{subcommands_help()}",
                targets=True, examples=EXAMPLES, parents=[job_options(
                    "print a line for every case (a terminal and a log show only those "
                    "that did not PASS)", seed=SEED_HELP, cases=True,
                    jobs="run the targets in N parallel processes: one report per target "
                         "under reports/<run id>/ and a summary across them")])
    ap.add_argument("--target", action="append", default=[],
                    help="where the suite runs (forms below; default: the embedded "
                         "emulator on every profile); repeatable")
    ap.add_argument("--profile", help="the behaviour expected of a serial/tcp/exec target "
                                      "(with no --target: run the emulator as this profile); "
                                      "'auto': ask the unit (? and Q) and choose")
    ap.add_argument("--variant", help="with --profile auto, where the unit's answer does not "
                    "say it: the variant (e.g. 100 for a GVE84-100)")
    ap.add_argument("--yes", action="store_true",
                    help="real units: move without asking first (unattended benches)")
    ap.add_argument("--operator", action=argparse.BooleanOptionalAction, default=None,
                    help="real units: a technician stands in for the test rig (ground an "
                         "input, cycle the power, read the outputs; each step read back, "
                         "s skips it); default: when standard input is a terminal")
    ap.add_argument("--settings", default=None, choices=sorted(PROFILES),
                    help="Hypothesis settings profile (default: ci in virtual time, the "
                         "emulator's or a co-simulator's; hardware on serial/tcp/exec "
                         "targets)")
    ap.add_argument("--max-travel", type=positive, default=DEFAULT_MAX_TRAVEL,
                    help="real units: the motion envelope in full steps per axis either side "
                         "of where the run began (default %(default)s)")
    ap.add_argument("--allow-destructive", action="store_true",
                    help="real units: allow J, W and EEPROM writes (EEPROM backed up and "
                         "restored)")
    ap.add_argument("--mutant", help="emulator targets: plant this deliberate bug")
    ap.add_argument("--strict", action="store_true",
                    help="grade a serial/tcp/exec target by the project's decisions too: a "
                         "[D] difference FAILs instead of NON-STRICT (the embedded emulator "
                         "always is)")
    ap.add_argument("--hypothesis-db", metavar="DIR|redis://HOST:PORT/N|none",
                    help="where the machines keep failing examples, tried first by the next "
                         "run (redis: by every bench sharing it); default: "
                         f"REPORT_DIR/{DEFAULT_DATABASE}, none with --no-reports")
    ap.add_argument("--full-logs", action="store_true",
                    help="whole wire logs in the reports for passing cases too")
    ap.add_argument("--operator-name", default="", metavar="NAME",
                    help="who ran the suite, for the report")
    ap.add_argument("--list", action="store_true", help="list the cases and exit")
    ap.add_argument("--coverage", nargs="?", const="unit", choices=("unit", "host"),
                    help="print which rules of the spec the (selected) cases can fail, per "
                         "section and profile, and the rules without one (exit 1 if any)")
    return ap.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    try:
        args = parse_args(argv)
    except UsageError as err:
        print(f"{PROG}: {err}", file=sys.stderr)
        return 2
    return execute(args, argv)


def execute(args: argparse.Namespace, argv: list[str]) -> int:
    """The run that ``argv`` (parsed as ``args``) asks for; also what each process of a
    fleet runs for its one target (cli/fleet.py)."""
    try:
        return _main(args, argv)
    except UsageError as err:
        print(f"{PROG}: {err}", file=sys.stderr)
        return 2
    except Stopped as err:
        print(f"{PROG}: {err}", file=sys.stderr)
        return INTERRUPTED
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


def _nothing(text: str = "") -> None:
    """What -q prints of every line but the last."""


def example_database_of(args: argparse.Namespace) -> str | None:
    """Where the run keeps failing examples (docs/ci.md): --hypothesis-db, else a folder
    beside the reports (nowhere when the run writes no reports)."""
    if args.hypothesis_db is not None:
        return args.hypothesis_db
    return None if args.no_reports else str(Path(args.report_dir, DEFAULT_DATABASE))


def _main(args: argparse.Namespace, argv: list[str]) -> int:
    cases = chosen_cases(args)
    if args.list:
        for c in cases:
            print(f"{c.id:48} {c.tag:6} {c.rule}")
        return 0
    if args.coverage:
        if args.coverage == "host":
            import conformance.host.oracle  # noqa: F401  (registers the host checks)
        profiles = [args.profile] if args.profile else None
        try:
            report = coverage(profiles, role=args.coverage, cases=cases)
        except ProfileError as err:
            raise UsageError(str(err)) from None
        except LookupError as err:
            raise UsageError(str(err).strip("'\"")) from None
        print(format_coverage(report, args.coverage))
        # a gate for CI: a rule no case can fail is a defect of the suite
        return 1 if any(pc.uncovered or (pc.matrix and pc.matrix.lacking)
                        for pc in report) else 0
    if not args.no_reports:
        writable_folder(args.report_dir)
    with ExitStack() as run_scope:
        if not args.no_reports:         # the run's folder, before anything is sent
            folder = claimed(args.report_dir, args.run_id)
            args.run_id = folder.name
            run_scope.callback(release, folder)      # given back if nothing was written
        try:
            run_scope.enter_context(example_database(example_database_of(args)))
        except ValueError as err:
            raise UsageError(f"--hypothesis-db: {err}") from None
        return _run(args, argv, cases)


def _run(args: argparse.Namespace, argv: list[str], cases: list) -> int:
    console = Console()
    if args.profile == "auto":       # asking a unit on a port who it is sends `?` and `Q`
        unattended_specs([t for t in args.target if t.startswith(("serial:", "tcp:"))],
                         args.yes, console)
    try:
        targets, how = _targets(args, console)
    except KeyboardInterrupt:
        raise Stopped("interrupted before the run, nothing was sent") from None
    _preflight(targets)
    unattended(targets, args.yes, console)
    run_id = args.run_id or new_run_id()
    seed = run_seed([settings_for(t, args.settings) for t in targets], args.seed)
    meta = _meta(args, argv, targets, how, cases, seed, console)
    if args.jobs > 1 and len(targets) > 1:
        return _fleet(args, argv, targets, meta, console, run_id)
    if meta.confirmed == ASKED:
        for target in targets:
            consent(args.yes, console, meta).arm(target)
    say = _nothing if args.quiet else _say       # -q: the last line only
    say(f"Hypothesis settings: {_settings_line(targets, args.settings)}")
    say(f"seed {seed} (the same examples again: --seed {seed})" if seed is not None else
        "seed: none (derandomized settings draw the same examples every run; --seed N for "
        "others)")
    colour = wanted(getattr(args, "color", "auto"), sys.stdout)
    progress = Progress(len(targets) * len(cases), quiet=args.quiet,
                        verbose=getattr(args, "verbose", False), colour=colour)
    try:
        result = run(targets, cases, settings_name=args.settings, run_id=run_id,
                     on_result=progress.result, seed=seed,
                     console=console if meta.operator_steps else None)
    finally:
        progress.close()
    meta.finished = now_iso()
    _from_sessions(result, meta)
    result.meta = meta
    say(f"\n{len(result.results)} case runs on {len(targets)} target(s): {counted(result)}")
    say(f"took {result.seconds:.1f} s, {result.frames} frames exchanged"
        f"{' (interrupted by Ctrl-C)' if result.interrupted else ''}")
    for line in _session_lines(result):
        say(line)
    return end(result, None if args.no_reports else args.report_dir,
               junitxml=args.junitxml, colour=colour,
               accept_incomplete=args.accept_incomplete)


class Stopped(Exception):
    """Ctrl-C before the run sent anything: one line, exit status INTERRUPTED."""


def _fleet(args: argparse.Namespace, argv: list[str], targets: list[Target], meta: RunMeta,
           console: Console, run_id: str) -> int:
    """The targets in processes of their own (cli/fleet.py), asked about once here: the
    members have no terminal."""
    from conformance.cli.fleet import run_fleet
    if meta.confirmed == ASKED and not confirmed(targets, meta, console):
        raise UsageError("motion not confirmed, nothing that moves was sent (answer y, or "
                         "give --yes on an unattended bench)")
    for target in targets:
        target.close()              # each member opens its own port
    return run_fleet(args, argv, targets, run_id, meta.seed, example_database_of(args))


def _meta(args: argparse.Namespace, argv: list[str], targets: list[Target], how: list[str],
          cases: list, seed: int | None, console: Console) -> RunMeta:
    """What the reports say about the run before it starts."""
    meta = RunMeta(started=now_iso(), operator=args.operator_name, command=argv,
                   settings=_settings_line(targets, args.settings), seed=seed,
                   mutant=args.mutant, destructive=args.allow_destructive,
                   max_travel=args.max_travel, cases=args.cases, exclude=args.exclude,
                   full_logs=args.full_logs, strict=args.strict)
    for target, chosen in zip(targets, how, strict=True):
        t = meta.target(target.info.spec)
        t.kind, t.profile, t.profile_chosen = target.info.kind, target.profile.name, chosen
        t.envelope = target.info.max_travel if target.info.real else None
        t.graded = "strict" if target.info.strict else "by the tags"
    meta.coverage = [{**d, "sections": [{**s, "covered": len(s["covered"])}
                                        for s in d["sections"]]}
                     for d in (pc.as_dict() for pc in coverage(
                         sorted({t.profile.name for t in targets}), cases=cases))]
    real = any(t.info.real for t in targets)
    meta.operator_steps = (real and console.interactive if args.operator is None
                           else args.operator)
    meta.confirmed = consent(args.yes, console, meta).how(targets)
    try:
        record_identities([t for t in targets if not t.info.real], meta)
    except (OSError, SerialException, ValueError) as err:
        raise UsageError(str(err)) from None
    return meta


def _from_sessions(result: RunResult, meta: RunMeta) -> None:
    """What each real unit's session found (its identity) and saw (the largest
    excursion per axis), into the run's metadata."""
    for spec, s in result.sessions.items():
        t = meta.target(spec)
        if s["identity"]:
            t.version = s["identity"].get("version", t.version)
            t.processor_id = s["identity"].get("processor_id", t.processor_id)
        if s.get("line"):
            t.line = s["line"]
        if s["excursion"]:
            t.excursion = [max(abs(lo), abs(hi)) for lo, hi in s["excursion"]]


def _targets(args: argparse.Namespace, console: Console) -> tuple[list[Target], list[str]]:
    """The targets, and how each one's profile was chosen (``--profile auto`` asks)."""
    every = [f"emu:{name}" for name in available_profiles()]
    if args.profile and args.profile != "auto" and not args.target:
        every = [f"emu:{args.profile}"]   # no target: the emulator behaving as --profile
    # no --target, or emu:all: the embedded emulator on every profile (--profile is for
    # the targets named)
    specs = [(s, t.split("?")[0] != "emu:all") for t in args.target or ["emu:all"]
             for s in (_with_query(every, t) if t.split("?")[0] == "emu:all" else [t])]
    try:
        chosen = [resolve(s, args.profile if named else None, args.variant, console)
                  for s, named in specs]
        return [parse_target(s, profile=p, allow_destructive=args.allow_destructive,
                             max_travel=args.max_travel, mutant=args.mutant,
                             strict=args.strict)
                for s, p, _ in chosen], [how for _, _, how in chosen]
    except (ValueError, LookupError, OSError, SerialException) as err:
        raise UsageError(str(err).strip("'\"")) from None



def _with_query(specs: list[str], given: str) -> list[str]:
    """``emu:all?mutant=X``: each profile's target with the settings given (checked as
    any ``emu:`` target's are)."""
    query = given.partition("?")[2]
    return [f"{s}?{query}" if query else s for s in specs]


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
    kinds = {t.info.virtual_time for t in targets}
    parts = (["ci in virtual time"] if True in kinds else []) + \
        (["hardware on real units (no shrinking in real time)"] if False in kinds else [])
    return ", ".join(parts) + " (--settings to choose)"


def _session_lines(result: RunResult) -> list[str]:
    """Per real target: the largest excursion, what was restored, what could not be,
    where the time went."""
    lines = []
    for spec, s in result.sessions.items():
        if not s["real"]:
            continue
        lines.append(f"{spec} ({s['profile']}"
                     + (f", {escaped(s['identity'].get('version', ''))}" if s["identity"] else "")
                     + "):")
        if s["excursion"]:
            axes = ", ".join(f"{a} {lo:+g}..{hi:+g}" for a, (lo, hi)
                             in zip(s["axes"], s["excursion"], strict=True))
            lines.append(f"  largest excursion (full steps, envelope ±{s['max_travel']}): {axes}")
        lines += [f"  restored: {r}" for r in s["restored"]]
        lines += [f"  reset: {r}" for r in s["reset"]]
        lines += [f"  {line}" for line in account_lines(s.get("time") or {})]
    lines += [f"PROBLEM: {p}" for p in result.problems]
    return lines


if __name__ == "__main__":
    sys.exit(main())
