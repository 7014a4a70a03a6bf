"""The whole catalogue through a co-simulator against the embedded emulator: `exec:` of
`python -m emulator --model GVE84-100 --cosim` (docs/cosim.md: virtual time over the
text protocol, judged as a unit that is not the suite's own: the known state before each
case, the envelope, the restorations) and `emu:GVE84-100`, each run's time from the
program's start to its end, and their ratio (goal: at most 3).

    python -m bench.bench_cosim [--profile P]
"""

from __future__ import annotations

import argparse
import shlex
import sys
import time

from conformance.run.runner import run
from conformance.run.selection import select
from conformance.targets import Target, parse_target

GOAL = 3.0


def timed(target: Target) -> tuple[float, int, dict[str, str]]:
    """(seconds, frames, verdicts) of the catalogue on ``target``."""
    start = time.perf_counter()
    target.preflight()
    result = run([target], select([]))
    return (time.perf_counter() - start, result.frames,
            {r.id: r.verdict for r in result.results})


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(prog="bench_cosim")
    ap.add_argument("--profile", default="GVE84-100")
    args = ap.parse_args(argv)
    command = [sys.executable, "-m", "emulator", "--model", args.profile, "--cosim"]
    emu_s, emu_frames, emu = timed(parse_target(f"emu:{args.profile}"))
    cosim_s, cosim_frames, cosim = timed(parse_target(
        "exec:" + shlex.join(command), profile=args.profile, allow_destructive=True))
    same = sum(emu[k] == cosim[k] for k in emu)
    print(f"the catalogue on {args.profile}, through a co-simulator and in process")
    print(f"  emu:             {emu_s:6.2f} s  {emu_frames:6d} frames "
          f"({emu_frames / emu_s:6.0f}/s)")
    print(f"  exec: --cosim    {cosim_s:6.2f} s  {cosim_frames:6d} frames "
          f"({cosim_frames / cosim_s:6.0f}/s; the known state before each case)")
    print(f"  ratio            {cosim_s / emu_s:6.2f} x the emu: time (goal <= {GOAL:g}); "
          f"{same} of {len(emu)} verdicts the same (the rest: the envelope)")


if __name__ == "__main__":
    main()
