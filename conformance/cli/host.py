"""`gve-conformance host`: certify a host program — the suite plays the unit.

    gve-conformance host --profile GVE84-100 -- python -m gve_host {port} --job J
    gve-conformance host --profile GVE84-100                     (attended)

Launched: the command after `--` is started once per scenario, `{port}` replaced by the
port to open (a pseudo-terminal path, or `socket://HOST:PORT` with --port tcp:...).
Attended (no command): the port is printed first; the operator runs the host for each
scenario and types `done`, `failed` or `hung` when its job has ended.
Exit status: 0 when nothing FAILs, 1 otherwise, 2 for usage errors.

The command line of conformance/host/ (one meaning under one name).
"""

from __future__ import annotations

import argparse
import fnmatch
import sys

from conformance.cli.colour import wanted
from conformance.cli.ending import claimed, counted, end, new_run_id, progress, result_line
from conformance.cli.progress import HEARTBEAT, Progress
from conformance.cli.usage import (
    Parser,
    UsageError,
    job_options,
    positive,
    seconds,
    summary,
    writable_folder,
)
from conformance.host.certify import CLEAN_LIMIT_S, HostStartError, Plan, certify
from conformance.host.played_units import check_readings, load_units
from conformance.host.ports import open_port
from conformance.host.scenarios import SCENARIOS, select
from conformance.operator.console import Console
from conformance.reports.files import release
from conformance.run.runner import CaseResult
from conformance.verdicts.explain import reason
from conformance.verdicts.verdict import PASS
from gve_fixtures.profile import Profile, ProfileError

#: where the played unit is served to the host (--port), for --help
PORT_FORMS = """\
ports (--port): the suite plays the unit here, the host opens it ({port} in its command)
  pty                               a new pseudo-terminal (default)
  tcp:HOST:PORT                     a raw TCP port (the host opens socket://HOST:PORT;
                                    port 0 picks a free one)
  /dev/ttyX                         a serial device, to a host on another machine"""
#: why an attended certification (no host command) does not start without a terminal
NOBODY_TO_SAY = ("attended (no host command): someone at a terminal says how each job "
                 "ended, and standard input is not a terminal; give the host's command "
                 "after --")
EXAMPLES = (
    "gve-conformance host --profile GVE84-100 -- python -m gve_host {port} "
    "--job gve_host/jobs/square.job",
    "gve-conformance host --profile GVE114-500 --port tcp:127.0.0.1:0 -- ./my-host {port}",
    "gve-conformance host --profile GVE84-100                 # attended: you run the host",
)


def parse_args(argv: list[str]) -> argparse.Namespace:
    command: list[str] = []
    if "--" in argv:
        at = argv.index("--")
        argv, command = argv[:at], argv[at + 1:]
    ap = Parser(prog="gve-conformance host", description=summary(__doc__),
                epilog=PORT_FORMS, examples=EXAMPLES, parents=[job_options(
                    "print a line for every scenario (the default)", seed=None,
                    jobs="scenarios run side by side (launched, pty or tcp port 0)",
                    jobs_default=4)])
    ap.add_argument("--profile", help="the unit played to the host, at its default address")
    ap.add_argument("--unit", action="append", default=[], metavar="MODEL@ADDRESS",
                    help="a unit on the line (repeatable; instead of --profile)")
    ap.add_argument("--scenarios", action="append", default=[], metavar="GLOB",
                    help="run only these scenarios (the clean run always runs)")
    ap.add_argument("--baud", type=positive, help="the line's baud rate (default: the profile's)")
    ap.add_argument("--host-timeout", type=seconds, default=5.0, metavar="S",
                    help="a host silent this long without exiting hangs (default 5)")
    ap.add_argument("--clean-limit", type=seconds, default=CLEAN_LIMIT_S, metavar="S",
                    help="the longest the host's job may take on the clean line (default "
                         f"{CLEAN_LIMIT_S:.0f}); a fault run may take twice the clean "
                         "run's length")
    ap.add_argument("--reading", action="append", default=[], metavar="NAME",
                    help="the played unit reads a silence of the manuals as NAME "
                         "(repeatable; the readings of emulator/readings.py, listed when a "
                         "name is unknown): play the reading the host was written for")
    ap.add_argument("--port", default="pty",
                    help="pty (default), tcp:HOST:PORT, or a serial device path")
    ap.add_argument("--strict", action="store_true",
                    help="the host claims the project's decisions: [D] rules FAIL too")
    ap.add_argument("--expect-motion", action="append", default=[],
                    metavar="[ADDRESS:]X,Y,...",
                    help="the full steps each axis travels in the host's job (the sum of "
                         "its vectors' lengths): the clean run must execute exactly that "
                         "(2.link.host-drives); per unit, default its first")
    ap.add_argument("--list", action="store_true", help="list the scenarios and exit")
    args = ap.parse_args(argv)
    args.command = command or None
    return args


def plan_of(args: argparse.Namespace) -> Plan:
    if bool(args.profile) == bool(args.unit):
        raise UsageError("give --profile, or --unit MODEL@ADDRESS (repeatable)")
    try:
        units = load_units(args.unit or [args.profile])
    except (ValueError, LookupError, ProfileError) as err:
        raise UsageError(str(err).splitlines()[0]) from None
    baud = args.baud or units[0][0].default_baud
    unsupported = [p.name for p, _ in units if baud not in p.bauds]
    if unsupported:
        raise UsageError(f"--baud {baud}: the {', '.join(unsupported)} does not run at it "
                    f"(it runs at {', '.join(map(str, units[0][0].bauds))})")
    if args.port != "pty":
        try:                    # a port that cannot be opened is a usage error, not a run
            open_port(args.port, baud).close()
        except ValueError as err:
            raise UsageError(str(err)) from None
    if args.command and not any("{port}" in a for a in args.command):
        raise UsageError("the host command must name the port as {port}")
    unmatched = [p for p in args.scenarios if not any(
        fnmatch.fnmatchcase(s.name, p) or fnmatch.fnmatchcase(s.id, p) for s in SCENARIOS)]
    if unmatched:
        raise UsageError(f"no scenario matches {' '.join(unmatched)} (see --list)")
    try:
        readings = check_readings(args.reading)
    except ValueError as err:
        raise UsageError(f"--reading: {err}") from None
    scenarios = select(args.scenarios)
    return Plan(units, baud, scenarios, args.command, args.port, args.host_timeout,
                args.strict, args.jobs, expect_motion_of(args.expect_motion, units),
                clean_limit=args.clean_limit, readings=readings)


def expect_motion_of(given: list[str], units: list[tuple[Profile, int]]
                     ) -> dict[int, tuple[int, ...]] | None:
    """``--expect-motion [ADDRESS:]X,Y,...`` per unit on the line, or None."""
    out: dict[int, tuple[int, ...]] = {}
    axes = {address: profile.axes for profile, address in units}
    for text in given:
        where, _, steps = text.rpartition(":")
        try:
            address = int(where) if where else units[0][1]
            travel = tuple(int(v) for v in steps.split(","))
        except ValueError:
            raise UsageError(f"--expect-motion {text}: give [ADDRESS:]X,Y,... in whole "
                             "full steps, e.g. 1000,500,0") from None
        if address not in axes:
            raise UsageError(f"--expect-motion {text}: no unit at address {address} "
                             f"(the line has {', '.join(map(str, axes))})")
        if len(travel) > len(axes[address]) or any(v < 0 for v in travel):
            raise UsageError(f"--expect-motion {text}: at most {len(axes[address])} "
                             f"travels ({', '.join(axes[address])}), none negative")
        if address in out:
            raise UsageError(f"--expect-motion: unit {address} given twice")
        out[address] = travel
    return out or None


def flags_of(args: argparse.Namespace, plan: Plan) -> dict[str, object]:
    """The options in force for a certification, by their command-line names."""
    return {"--profile" if args.profile else "--unit": plan.profile,
            "--baud": plan.baud, "--port": plan.port,
            "--scenarios": " ".join(args.scenarios) or "all",
            "--host-timeout": plan.host_timeout, "--clean-limit": plan.clean_limit,
            "--reading": " ".join(plan.readings) or "none (the project's decisions)",
            "--jobs": plan.jobs,
            "--strict": plan.strict,
            "--expect-motion": " ".join(args.expect_motion) or "none (not judged)",
            "wire logs": "whole, every scenario"}


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    try:
        args = parse_args(argv)
        if args.list:
            for sc in SCENARIOS:
                print(f"{sc.id:32} {sc.title}")
            return 0
        plan = plan_of(args)
        if not args.no_reports:
            writable_folder(args.report_dir)
        if plan.command is None and not Console().interactive:
            raise UsageError(NOBODY_TO_SAY)
        folder = None if args.no_reports else claimed(args.report_dir, args.run_id)
    except UsageError as err:
        print(f"gve-conformance host: {err}", file=sys.stderr)
        return 2
    def why(r: CaseResult) -> str | None:
        """Why a scenario did not pass: its deciding check, or why it did not run."""
        return reason(r).line() if r.verdict != PASS else None

    # a launched host's scenarios run on their own: a bar on a terminal, a line at least
    # every HEARTBEAT seconds in a log; an attended one's operator reads the console
    shown = None if plan.command is None else Progress(
        len(plan.scenarios), unit="scenario", quiet=args.quiet, verbose=True,
        every_step=True, heartbeat=HEARTBEAT)
    try:
        run_id = (args.run_id or new_run_id()) if folder is None else folder.name
        on_result = progress(args.quiet, why) if shown is None else (
            lambda r: shown.step(result_line(r, why(r))))
        result = certify(plan, run_id, on_result, console=sys.stdout, operator=sys.stdin)
    except (HostStartError, ValueError) as err:
        if folder is not None:
            release(folder)
        print(f"gve-conformance host: {err}", file=sys.stderr)
        return 2
    finally:
        if shown is not None:
            shown.close()
    result.meta.command = ["host", *argv]
    result.meta.host_command = list(args.command or [])
    result.meta.host_flags = flags_of(args, plan)
    if not args.quiet:
        stopped = " (interrupted by a signal: the hosts were stopped)"
        print(f"\n{len(result.results)} scenarios on {plan.profile}: {counted(result)}"
              f"{stopped if result.interrupted else ''}")
        clean = next((r for r in result.results if r.id.endswith(".clean")), None)
        if clean is not None:
            print(f"took {result.seconds:.1f} s; the job took {clean.seconds:.2f} s on the "
                  f"clean line; {result.frames} frames")
    return end(result, None if args.no_reports else args.report_dir, junitxml=args.junitxml,
               accept_incomplete=args.accept_incomplete,
               colour=wanted(args.color, sys.stdout))


if __name__ == "__main__":
    sys.exit(main())
