"""Where a real-line run's time goes: the catalogue against the emulator on a
pseudo-terminal paced at each baud rate (`python -m emulator --pty --baud B`, judged as
a real unit through `serial:`), and the session's time account (conformance/link/
account.py): each head's share of the wall time, and the suite's own waits and work
(goal: at most a tenth of the run, no wait the manual requires shortened).

    python -m bench.bench_line [--profile P] [--baud B ...] [--cases GLOB ...]
"""

from __future__ import annotations

import argparse
import subprocess
import sys

from conformance.link.account import Spent, suite_share
from conformance.run.runner import run
from conformance.run.selection import select
from conformance.targets import parse_target

GOAL = 0.10
BAUDS = (38400, 115200)


def accounted(profile: str, baud: int, cases: list[str] | None) -> tuple[dict[str, float],
                                                                          int]:
    """The time account and the frames of the catalogue over a line paced at ``baud``."""
    emulator = subprocess.Popen([sys.executable, "-m", "emulator", "--model", profile,
                                 "--pty", "--baud", str(baud)], stdin=subprocess.DEVNULL,
                                stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    try:
        port = emulator.stdout.readline().strip()
        target = parse_target(f"serial:{port}?baud={baud}", profile=profile)
        result = run([target], select(cases))
    finally:
        emulator.terminate()
        emulator.wait(10)
    (totals,) = [s["time"] for s in result.sessions.values()]
    return totals, result.frames


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(prog="bench_line")
    ap.add_argument("--profile", default="GVE84-100")
    ap.add_argument("--baud", type=int, action="append", default=[])
    ap.add_argument("--cases", action="append", default=[], metavar="GLOB")
    args = ap.parse_args(argv)
    print(f"the catalogue on {args.profile} over a pty paced at the baud rate: where the "
          "time went (shares of the wall time)")
    for baud in args.baud or BAUDS:
        totals, frames = accounted(args.profile, baud, args.cases or None)
        wall = totals["wall"]
        heads = ", ".join(f"{s} {totals[str(s)] / wall:.2f}" for s in Spent
                          if totals.get(str(s)))
        share = suite_share(totals)
        print(f"  {baud:6d} Bd  {wall:6.1f} s, {frames} frames: {heads}")
        print(f"            the suite's own waits and work {share:.2f} of the run "
              f"(goal <= {GOAL:.2f}: {'met' if share <= GOAL else 'NOT met'})")


if __name__ == "__main__":
    main()
