"""`python -m emulator` / `gve-emulator`: emulated units on a pseudo-terminal or TCP port.

    python -m emulator --model GVE114-500 --pty       # prints the pty's path first
    python -m emulator --unit GVE54@1 --unit GVE84-100@0 --tcp 127.0.0.1:5114

Serves in real time until SIGINT/SIGTERM (or `quit` on the control channel: standard
input, one command a line: `in 1 7F`, `switch Y -1500`, `power-on`, `state`, `quit`).
"""

from __future__ import annotations

import argparse
import sys

from emulator.link.clock import RealClock
from emulator.link.line import Line
from emulator.link.server import serve_pty, serve_tcp, stdin_or_none
from emulator.link.url import DEFAULT_MODEL, LineSpec, parse_unit
from emulator.mutants import MUTANTS


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    ap = argparse.ArgumentParser(prog="gve-emulator", description=__doc__.splitlines()[0])
    ap.add_argument("--model", default=None, help=f"unit profile (default {DEFAULT_MODEL})")
    ap.add_argument("--address", type=int, default=None, help="the unit's address 0..7")
    ap.add_argument("--unit", action="append", default=[], metavar="MODEL@ADDRESS",
                    help="a unit on the line (repeatable)")
    where = ap.add_mutually_exclusive_group(required=True)
    where.add_argument("--pty", action="store_true", help="serve on a new pseudo-terminal")
    where.add_argument("--tcp", metavar="HOST:PORT", help="serve raw bytes on a TCP port")
    ap.add_argument("--baud", type=int, default=None,
                    help="pace bytes at this rate (default: delivered at once)")
    ap.add_argument("--eeprom", metavar="FILE", help="EEPROM image (kept across restarts)")
    ap.add_argument("--log", metavar="FILE", help="write a transcript of the wire")
    ap.add_argument("--watchdog-ms", type=int, default=None)
    ap.add_argument("--mutant", choices=sorted(MUTANTS), help="plant one deliberate bug")
    ap.add_argument("--stepper", choices=["c", "python"], default=None)
    return ap.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    units = [parse_unit(u) for u in args.unit]
    if not units:
        units = [(args.model or DEFAULT_MODEL, args.address)]
    spec = LineSpec(units=units, baud=args.baud, watchdog_ms=args.watchdog_ms,
                    eeprom=args.eeprom, mutant=args.mutant, stepper=args.stepper, log=args.log)
    try:
        built = spec.build_units()
    except (ValueError, OSError) as err:
        print(f"gve-emulator: {err}", file=sys.stderr)
        return 2
    line = Line(built, spec.line_baud(built), clock=RealClock(), log=args.log,
                paced=args.baud is not None)
    control = stdin_or_none()
    if args.pty:
        serve_pty(line, control)
    else:
        host, _, port = args.tcp.rpartition(":")
        serve_tcp(line, host or "127.0.0.1", int(port), control)
    if line.log is not None:
        line.log.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
