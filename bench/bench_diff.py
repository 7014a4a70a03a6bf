"""The differential fuzzer in process: the emulator against a mutant of itself (and
against itself), frames per second with the search's own overhead (drawing, shrinking),
and the time 10,000 frames take as a ratio of the issue's 10 s budget (below 1: met).

    python -m bench.bench_diff [--frames N]
"""

from __future__ import annotations

import argparse

from conformance.diff.engine import Budget, Pair, search
from conformance.diff.grammar import Options
from conformance.diff.sides import Side
from conformance.targets import parse_target

BUDGET_FRAMES = 10_000
BUDGET_SECONDS = 10.0


def frames_per_second(mutant: str | None, frames: int) -> tuple[float, int]:
    spec = "emu:GVE84-100" + (f"?mutant={mutant}" if mutant else "")
    target, reference = parse_target(spec), parse_target("emu:GVE84-100")
    pair = Pair(Side(target), Side(reference), target.profile)
    budget = Budget(examples=None)
    total = 0.0
    found = 0
    # searches of 500 sequences (a run's is one of 2000) until the frames are sent, the
    # probes before the first only (a run sends them once); a finding ends one search,
    # the next goes on
    while budget.frames < frames:
        first = budget.used == 0
        budget.examples = budget.used + 500
        found += len(search(pair, Options(destructive=True, rig=True), budget,
                            seed=budget.used, with_probes=first))
    total = budget.elapsed
    return budget.frames / total, found


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(prog="bench_diff")
    ap.add_argument("--frames", type=int, default=BUDGET_FRAMES)
    args = ap.parse_args(argv)
    print("differential fuzzer, in process (GVE84-100, virtual time on both sides)")
    for mutant in (None, "velocity-ignored"):
        rate, found = frames_per_second(mutant, args.frames)
        ten_k = BUDGET_FRAMES / rate
        print(f"  against {mutant or 'itself':18} {rate:8.0f} frames/s  "
              f"10,000 frames in {ten_k:5.2f} s = {ten_k / BUDGET_SECONDS:4.2f} x the 10 s "
              f"budget  ({found} finding(s))")


if __name__ == "__main__":
    main()
