"""`python -m emulator` / `gve-emulator`: emulated units on a pseudo-terminal or TCP port,
or in co-simulation on standard input and output.

    python -m emulator --model GVE114-500 --pty       # prints the pty's path first
    python -m emulator --unit GVE54@1 --unit GVE84-100@0 --tcp 127.0.0.1:5114
    python -m emulator --model GVE84-100 --cosim      # prints `cosim 1` first

Serves in real time until SIGINT/SIGTERM (or `quit` on the control channel: standard
input, one command a line: `in 1 7F`, `switch Y -1500`, `power-on`, `state`, `quit`;
docs/rig.md). With --cosim the line runs in virtual time, its clock moved only by the
commands on standard input (docs/cosim.md), until `quit` or the end of that input. A
usage error is one line on stderr and exit status 2.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from typing import NoReturn

from emulator.link.clock import RealClock
from emulator.link.cosim import serve_cosim
from emulator.link.line import Line
from emulator.link.server import (
    PtyHost,
    StdoutGone,
    TcpHost,
    control_fd,
    say,
    serve,
    silence_stdout,
)
from emulator.link.url import DEFAULT_MODEL, LineSpec, parse_address, parse_unit, positive
from emulator.mutants import MUTANTS
from emulator.readings import READINGS

PROG = "gve-emulator"


class UsageError(Exception):
    pass


class Parser(argparse.ArgumentParser):
    """Usage errors in one line (and exit status 2), like every other error here."""

    def error(self, message: str) -> NoReturn:
        raise UsageError(message)


class _Version(argparse.Action):
    def __init__(self, option_strings: list[str], dest: str = argparse.SUPPRESS,
                 **kwargs: object) -> None:
        super().__init__(option_strings, dest, nargs=0, default=argparse.SUPPRESS,
                         **kwargs)  # type: ignore[arg-type]

    def __call__(self, parser: argparse.ArgumentParser, *_: object) -> None:
        from emulator.about import version_text
        print(version_text(PROG))
        parser.exit(0)


def _address(text: str) -> int:
    try:
        return parse_address(text)
    except ValueError as err:
        raise argparse.ArgumentTypeError(str(err)) from None


def _positive(text: str) -> int:
    try:
        return positive("the value", text)
    except ValueError as err:
        raise argparse.ArgumentTypeError(str(err)) from None


def tcp_address(text: str) -> tuple[str, int]:
    """HOST:PORT (HOST defaults to 127.0.0.1; PORT 0 picks a free one)."""
    host, colon, port = text.rpartition(":")
    if not colon or not (port.isascii() and port.isdigit()) or int(port) > 65535:
        raise UsageError(f"--tcp takes HOST:PORT with PORT 0..65535, not {text!r}")
    return host or "127.0.0.1", int(port)


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    ap = Parser(prog=PROG, description=__doc__,
                formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--version", action=_Version,
                    help="print the version, the C stepper core's state and the Python, "
                    "then exit")
    ap.add_argument("--model", default=None, help=f"unit profile (default {DEFAULT_MODEL})")
    ap.add_argument("--address", type=_address, default=None, help="the unit's address 0..7")
    ap.add_argument("--unit", action="append", default=[], metavar="MODEL@ADDRESS",
                    help="a unit on the line (repeatable)")
    where = ap.add_mutually_exclusive_group(required=True)
    where.add_argument("--pty", action="store_true", help="serve on a new pseudo-terminal")
    where.add_argument("--tcp", metavar="HOST:PORT", help="serve raw bytes on a TCP port")
    where.add_argument("--cosim", action="store_true",
                       help="co-simulation in virtual time on standard input and output "
                       "(docs/cosim.md)")
    ap.add_argument("--snapshot", action="store_true",
                    help="with --cosim: offer `snapshot` and `restore` (docs/cosim.md; by "
                    "fork, which costs more than the power-on a restore stands in for)")
    ap.add_argument("--baud", type=_positive, default=None,
                    help="pace bytes at this rate (default: delivered at once; with "
                    "--cosim the profile's rate until `baud N`)")
    ap.add_argument("--eeprom", metavar="FILE", help="EEPROM image (kept across restarts)")
    ap.add_argument("--log", metavar="FILE", help="write a transcript of the wire")
    ap.add_argument("--watchdog-ms", type=_positive, default=None)
    ap.add_argument("--mutant", choices=sorted(MUTANTS), metavar="NAME",
                    help="plant one deliberate bug (emulator/mutants.py)")
    ap.add_argument("--reading", action="append", default=[], choices=sorted(READINGS),
                    metavar="NAME", help="take another reading of a point the manuals leave "
                    "open (emulator/readings.py; repeatable)")
    ap.add_argument("--stepper", choices=["c", "python"], default=None)
    return ap.parse_args(argv)


def build(argv: list[str] | None) -> tuple[Line, PtyHost | TcpHost | None]:
    """The line and where it is served (None: co-simulation on standard input and
    output); every usage problem raises UsageError."""
    args = parse_args(argv)
    try:
        units = [parse_unit(u) for u in args.unit]
        if not units:
            units = [(args.model or DEFAULT_MODEL, args.address)]
        spec = LineSpec(units=units, baud=args.baud, watchdog_ms=args.watchdog_ms,
                        eeprom=args.eeprom, mutant=args.mutant, stepper=args.stepper,
                        log=args.log, readings=tuple(args.reading))
        built = spec.build_units()
        if args.cosim:
            return Line(built, spec.line_baud(built), log=args.log), None
        place = tcp_address(args.tcp) if args.tcp else None
        line = Line(built, spec.line_baud(built), clock=RealClock(), log=args.log,
                    paced=args.baud is not None)
        host = PtyHost() if place is None else TcpHost(*place)
    except (ValueError, LookupError, ImportError) as err:
        raise UsageError(str(err)) from None
    except OSError as err:
        raise UsageError(f"{err.strerror or err}"
                         f"{f' ({err.filename})' if err.filename else ''}") from None
    return line, host


def main(argv: list[str] | None = None) -> int:
    try:
        line, host = build(argv)
    except UsageError as err:
        print(f"{PROG}: {err}", file=sys.stderr)
        return 2
    if host is None:
        with _ending_quietly(line):
            serve_cosim(line, snapshots=parse_args(argv).snapshot)
        return 0
    try:
        say(host.name)
    except StdoutGone:
        host.close()
        silence_stdout()
        return 0
    with _ending_quietly(line):
        serve(line, host, control_fd())
    return 0


@contextmanager
def _ending_quietly(line: Line) -> Iterator[None]:
    """Serve until done, or end quietly when the reader of stdout (the user, or the
    co-simulation's driver) went away; the line's transcript is closed either way."""
    try:
        yield
    except StdoutGone:
        silence_stdout()
    finally:
        if line.log is not None:
            line.log.close()


if __name__ == "__main__":
    sys.exit(main())
