"""`gve-conformance ports`: the serial ports of this machine (pyserial's ``list_ports``:
device, description, hardware id), so that a technician finds the unit's port. With
``--probe`` each port is also asked ``?`` at the profiles' baud rates and the unit that
answers is named; ``--glob`` adds ports the system does not list (a pty, a symlink).

The probe asks ``?`` and nothing else (framed as the suite frames it, once more with a
checksum when the unit answers that it wants one). A port another program holds (locked,
or ``TIOCEXCL``) is skipped untouched and said so; every port probed gets its terminal
settings back as they were found."""

from __future__ import annotations

import argparse
import glob
import sys

from serial.tools import list_ports

from conformance.cli.usage import Parser, UsageError, summary


def parse_args(argv: list[str]) -> argparse.Namespace:
    ap = Parser(prog="gve-conformance ports", description=summary(__doc__), examples=(
        "gve-conformance ports",
        "gve-conformance ports --probe                    # who answers `?` on each",
        "gve-conformance ports --glob '/dev/pts/*' --probe"))
    ap.add_argument("--glob", action="append", default=[], metavar="PATTERN",
                    help="also list devices matching PATTERN (e.g. '/dev/pts/*')")
    ap.add_argument("--probe", action="store_true",
                    help="ask each port `?` at the profiles' baud rates (only `?`, again with "
                         "a checksum if the unit wants one: it moves nothing) and show who "
                         "answers; ports held by another program are skipped, each port's "
                         "settings restored")
    return ap.parse_args(argv)


def found(patterns: list[str]) -> list[tuple[str, str, str]]:
    """(device, description, hardware id) of every port, the system's first."""
    ports = [(p.device, p.description, p.hwid)
             for p in sorted(list_ports.comports(include_links=True))]
    known = {device for device, _, _ in ports}
    for pattern in patterns:
        for device in sorted(glob.glob(pattern)):
            if device not in known:
                ports.append((device, "given by --glob", "n/a"))
                known.add(device)
    return ports


def main(argv: list[str]) -> int:
    try:
        args = parse_args(argv)
    except UsageError as err:
        print(f"gve-conformance ports: {err}", file=sys.stderr)
        return 2
    ports = found(args.glob)
    if not ports:
        print("no serial ports found (a USB adapter plugged in? try --glob)")
        return 0
    if args.probe:
        from conformance.targets.identify import probe
    width = max(len(device) for device, _, _ in ports)
    for device, description, hwid in ports:
        line = f"{device:{width}}  {description}  [{hwid}]"
        if args.probe:
            line += f"  -> {probe(device)}"
        print(line, flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
