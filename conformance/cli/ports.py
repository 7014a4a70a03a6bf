"""`gve-conformance ports`: the serial ports of this machine (pyserial's ``list_ports``:
device, description, hardware id), so that a technician finds the unit's port. With
``--probe`` each port is also asked ``?`` at the profiles' baud rates and the unit that
answers is named; ``--glob`` adds ports the system does not list (a pty, a symlink), and
a port named on the command line (``ports --probe PATH``) is listed and probed too.

The probe asks ``?`` and nothing else (framed as the suite frames it, once more with a
checksum when the unit answers that it wants one). A port another program holds (locked,
or ``TIOCEXCL``) is skipped untouched and said so; every port probed gets its terminal
settings back as they were found. A pseudo-terminal is probed only when it is named on
the command line: one a glob or a symlink found may be somebody's interactive terminal
or another program's line that holds no lock, and `!0?` typed into it is nobody's
business but its owner's."""

from __future__ import annotations

import argparse
import glob
import os
import re
import sys

from serial.tools import list_ports

from conformance.cli.usage import Parser, UsageError, job_options, summary

#: the device majors of Linux's pseudo-terminal slaves: the old BSD-style ones
#: (PTY_SLAVE_MAJOR) and UNIX98_PTY_SLAVE_MAJOR and up; a serial port (ttyS*: 4,
#: ttyUSB*: 188, ttyACM*: 166...) has another
_PTY_MAJORS = frozenset({3, *range(136, 144)})
#: pseudo-terminal slaves by name where the system has no majors to tell (BSD and macOS:
#: /dev/ttys003, the old ttyp0..ttysf); never asked on Linux, where /dev/ttyS0 is a port
_PTY_NAMES = re.compile(r"/dev/(pts/\d+|ttys\d+|tty[p-s][0-9a-f])\Z")
#: what a pseudo-terminal found by a glob or the system's list shows instead of a probe
NAME_IT = ("skipped: a pseudo-terminal (an interactive terminal, or another program's "
           "line): probed only when named, gve-conformance ports --probe {device}")


def parse_args(argv: list[str]) -> argparse.Namespace:
    ap = Parser(prog="gve-conformance ports", description=summary(__doc__), examples=(
        "gve-conformance ports",
        "gve-conformance ports --probe                    # who answers `?` on each",
        "gve-conformance ports --probe /dev/pts/7         # a simulator's pty, named",
        "gve-conformance ports --glob '/dev/pts/*'        # list the ptys too"),
        parents=[job_options("the same lines (every port is always listed)",
                             reports=False, seed=None)])
    ap.add_argument("device", nargs="*", metavar="PATH",
                    help="also list (and with --probe ask) this port; a pseudo-terminal is "
                         "probed only when named here")
    ap.add_argument("--glob", action="append", default=[], metavar="PATTERN",
                    help="also list devices matching PATTERN (e.g. '/dev/pts/*'; the "
                         "pseudo-terminals among them are not probed: name one as PATH)")
    ap.add_argument("--probe", action="store_true",
                    help="ask each port `?` at the profiles' baud rates (only `?`, again with "
                         "a checksum if the unit wants one: it moves nothing) and show who "
                         "answers; ports held by another program are skipped, each port's "
                         "settings restored")
    return ap.parse_args(argv)


def found(patterns: list[str], named: list[str] = ()) -> list[tuple[str, str, str]]:
    """(device, description, hardware id) of every port, the system's first."""
    ports = [(p.device, p.description, p.hwid)
             for p in sorted(list_ports.comports(include_links=True))]
    known = {device for device, _, _ in ports}
    for device in [d for pattern in patterns for d in sorted(glob.glob(pattern))]:
        if device not in known:
            ports.append((device, "given by --glob", "n/a"))
            known.add(device)
    for device in named:
        if device not in known:
            ports.append((device, "named", "n/a"))
            known.add(device)
    return ports


def is_pseudo_terminal(device: str) -> bool:
    """Whether ``device`` (or what its symlinks lead to) is a pseudo-terminal's slave:
    by what it is — its device major on Linux — and by its name only where there are
    no majors to tell (``/dev/ttyS0``, a serial port, is never taken for one)."""
    path = os.path.realpath(device)
    try:
        rdev = os.stat(path).st_rdev
    except OSError:
        return False
    if sys.platform.startswith("linux"):
        return os.major(rdev) in _PTY_MAJORS
    return _PTY_NAMES.match(path) is not None


def main(argv: list[str]) -> int:
    try:
        args = parse_args(argv)
    except UsageError as err:
        print(f"gve-conformance ports: {err}", file=sys.stderr)
        return 2
    ports = found(args.glob, args.device)
    if not ports:
        print("no serial ports found (a USB adapter plugged in? try --glob)")
        return 0
    if args.probe:
        from conformance.targets.identify import probe
    named = set(args.device)
    width = max(len(device) for device, _, _ in ports)
    said: list[str] = []
    for device, description, hwid in ports:
        line = f"{device:{width}}  {description}  [{hwid}]"
        if args.probe:
            asked = device in named or not is_pseudo_terminal(device)
            said.append(probe(device) if asked else NAME_IT.format(device=device))
            line += f"  -> {said[-1]}"
        print(line, flush=True)
    print(last_line(len(ports), said if args.probe else None), flush=True)
    return 0


def last_line(listed: int, said: list[str] | None) -> str:
    """What the listing found, as its last line: an inventory judges nothing, so no
    verdict word (docs/decisions.md); ``said``: what each probe said (None: no probe)."""
    from conformance.targets.identify import SILENT
    ports = f"{listed} port{'s' if listed != 1 else ''} listed"
    if said is None:
        return f"{ports}; none probed (--probe asks each who it is)"
    skipped = sum(s.startswith("skipped") for s in said)
    silent = sum(s == SILENT for s in said)
    return (f"{ports}; a GVE unit answered on {len(said) - skipped - silent}, no answer on "
            f"{silent}, {skipped} skipped untouched")


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
