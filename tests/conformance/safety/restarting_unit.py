"""A unit that restarts by itself (a brown-out, a watchdog reset): the emulator, served as
`python -m emulator` serves it (a pty, or co-simulation in virtual time), which at a
chosen frame loses that frame, is deaf for a while and comes back in its power-on state
(spec 9: counters 0, index 0, checksums off), its axes where they stopped.

    python -m tests.conformance.safety.restarting_unit --at 'SR6#3' --beyond X:1000 \\
        --moving --silence-ms 3500 -- --model GVE84-100 --cosim

``--at PATTERN#N``: the N-th frame for the unit whose body matches PATTERN (a regular
expression, from the body's start) while the other conditions hold; ``--beyond AXIS:P``
only while that axis is physically at least P counter units from where it started;
``--moving`` only while the axes move, ``--resting`` only while they do not. Once.
Everything after ``--`` is the emulator's command line.

Its control channel's `state` tells where the axes physically are and went (docs/rig.md),
and `restarted` how many times the unit restarted by itself; ``--no-rig`` makes `state`
an error, so that the suite finds no rig. ``--state FILE`` writes the `state` when the
program ends (the suite ends an exec: target's program itself), with ``restarted``: the
instant (ns) of each restart and where the axes physically were then."""

from __future__ import annotations

import argparse
import json
import re
import sys
from collections.abc import Callable

from emulator.__main__ import UsageError, _ending_quietly, build
from emulator.link import control
from emulator.link.cosim import serve_cosim
from emulator.link.server import control_fd, say, serve
from emulator.protocol.device import MS
from emulator.protocol.unit import Unit


def arm(unit: Unit, pattern: str, nth: int, silence_ms: int,
        when: Callable[[Unit, int], bool]) -> list[tuple[int, list[int]]]:
    """Make ``unit`` restart by itself at the ``nth`` frame matching ``pattern`` while
    ``when(unit, t)``; returns the list each restart's instant (ns) and the axes'
    physical position then are added to."""
    seen: list[int] = []
    restarts: list[tuple[int, list[int]]] = []
    take = unit._frame
    body = re.compile(pattern.encode())

    def frame(f, t: int) -> None:
        if not restarts and body.match(f.raw[2:]) and unit._address(f.raw) is not None \
                and when(unit, t):
            seen.append(t)
            if len(seen) == nth:
                restarts.append((t, list(unit.device.motion.physical(t))))
                unit.power_on(t)                       # the frame is lost with the power
                unit.device.deaf_until = t + silence_ms * MS
                return
        take(f, t)

    unit._frame = frame
    return restarts


def condition(beyond: str | None, moving: bool | None) -> Callable[[Unit, int], bool]:
    """Physically ``beyond`` (``AXIS:COUNTS``), and moving (True), resting (False) or
    either (None)."""
    axis, far = (beyond.split(":") if beyond else ("X", "0"))
    far = int(far)

    def holds(unit: Unit, t: int) -> bool:
        motion = unit.device.motion
        i = unit.profile.axes.index(axis.upper())
        return abs(motion.physical(t)[i]) >= far and \
            (moving is None or motion.flags(t).busy == moving)
    return holds


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    split = argv.index("--") if "--" in argv else len(argv)
    ap = argparse.ArgumentParser(prog="restarting_unit")
    ap.add_argument("--at", required=True, help="PATTERN#N")
    ap.add_argument("--beyond", default=None, help="AXIS:COUNTS")
    ap.add_argument("--moving", action="store_true")
    ap.add_argument("--resting", action="store_true")
    ap.add_argument("--no-rig", action="store_true")
    ap.add_argument("--silence-ms", type=int, default=3500)
    ap.add_argument("--state", default=None, help="FILE for the state at the end")
    args = ap.parse_args(argv[:split])
    pattern, _, nth = args.at.rpartition("#")
    try:
        line, host = build(argv[split + 1:])
    except UsageError as err:
        print(f"restarting_unit: {err}", file=sys.stderr)
        return 2
    moving = True if args.moving else False if args.resting else None
    restarts = arm(line.units[0], pattern, int(nth), args.silence_ms,
                   condition(args.beyond, moving))
    control.COMMANDS["restarted"] = (0, lambda line, a, at: str(len(restarts)))
    if args.no_rig:
        control.COMMANDS["state"] = (0, lambda line, a, at: "error: no rig here")
    try:
        with _ending_quietly(line):
            if host is None:
                serve_cosim(line)
            else:
                say(host.name)
                serve(line, host, control_fd())
    finally:
        if args.state:
            with open(args.state, "w") as out:
                json.dump({**line.state(), "restarted": restarts}, out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
