"""The differential fuzzer in process: the emulator against a mutant of itself (and
against itself), frames per second with the search's own overhead (drawing, shrinking),
and the time 10,000 frames take as a ratio of a 10 s budget (below 1: met);
then the same search through a co-simulator (`exec:` of `python -m emulator --cosim`,
docs/cosim.md: virtual time over the text protocol, each sequence begun at the
simulator's power-on through its rig), its sequences per second and their ratio to the
in-process figure; and the same ratio per CPU second (this process's and the
simulator's): on a loaded machine the two processes take turns and the wall-clock ratio
falls towards it, on an idle one the simulator runs beside the suite.

With ``--snapshot`` a third row: the co-simulator keeping its first power-on and
restoring it before each next sequence (`--cosim --snapshot`, Pair.restores,
docs/cosim.md): the same findings in fewer commands, each restore a fork of the emulator.

    python -m bench.bench_diff [--frames N] [--snapshot]
"""

from __future__ import annotations

import argparse
import resource
import shlex
import sys
import time

from conformance.diff.engine import Budget, Pair, search
from conformance.diff.grammar import Options
from conformance.diff.sides import Side
from conformance.link.safety import TargetNotResponding
from conformance.targets import parse_target

BUDGET_FRAMES = 10_000
BUDGET_SECONDS = 10.0


def cosim_spec(mutant: str | None, *, snapshot: bool = False) -> str:
    return "exec:" + shlex.join([sys.executable, "-m", "emulator", "--model", "GVE84-100",
                                 "--cosim", *(["--snapshot"] if snapshot else []),
                                 *(["--mutant", mutant] if mutant else [])])


def frames_per_second(mutant: str | None, frames: int, *, cosim: bool = False,
                      snapshot: bool = False) -> tuple[float, float, int]:
    """(frames/s, sequences/s, findings) of searches that send ``frames`` frames;
    ``snapshot``: through a co-simulator that restores its first power-on."""
    reference = parse_target("emu:GVE84-100")
    if cosim:
        target = parse_target(cosim_spec(mutant, snapshot=snapshot), profile="GVE84-100",
                              allow_destructive=True)
        target.preflight()
        side = Side(target, target.begin())
    else:
        target = parse_target("emu:GVE84-100" + (f"?mutant={mutant}" if mutant else ""))
        side = Side(target)
    pair = Pair(side, Side(reference), target.profile)
    pair.restores = snapshot
    try:
        return _search(pair, frames)
    finally:
        if cosim:
            target.session.finish()
            target.close()


def _cpu_seconds() -> float:
    """CPU seconds this process and its ended children (a simulator, once closed) used."""
    return sum(u.ru_utime + u.ru_stime for u in (resource.getrusage(resource.RUSAGE_SELF),
                                                 resource.getrusage(resource.RUSAGE_CHILDREN)))


def sequences_per_cpu_second(mutant: str | None, frames: int, *, cosim: bool = False,
                             snapshot: bool = False) -> tuple[float, float, int, float]:
    """:func:`frames_per_second`, and the sequences per CPU second of this process and the
    simulator's."""
    cpu, began = _cpu_seconds(), time.perf_counter()
    rate, sequences, found = frames_per_second(mutant, frames, cosim=cosim,
                                               snapshot=snapshot)
    wall, cpu = time.perf_counter() - began, _cpu_seconds() - cpu
    return rate, sequences, found, sequences * wall / cpu


def _search(pair: Pair, frames: int) -> tuple[float, float, int]:
    budget = Budget(examples=None)
    total = 0.0
    found = 0
    # searches of 500 sequences (a run's is one of 2000) until the frames are sent, the
    # probes before the first only (a run sends them once); a finding ends one search,
    # the next goes on
    while budget.frames < frames:
        first = budget.used == 0
        sent = budget.frames
        budget.examples = budget.used + 500
        try:
            found += len(search(pair, Options(destructive=True, rig=True), budget,
                                seed=budget.used, with_probes=first))
        except TargetNotResponding as err:
            # a finding of diff's (or the suite's own misjudgement): the figures are over
            # what ran, and the line says so
            print(f"  (the search stopped after {budget.frames} frames: {err})", flush=True)
            break
        if budget.frames == sent:
            break               # a target that stopped responding sends no more
    total = budget.elapsed
    return budget.frames / total, budget.used / total, found


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(prog="bench_diff")
    ap.add_argument("--frames", type=int, default=BUDGET_FRAMES)
    ap.add_argument("--snapshot", action="store_true",
                    help="a row more: the co-simulator restoring its first power-on")
    args = ap.parse_args(argv)
    print("differential fuzzer, in process (GVE84-100, virtual time on both sides)")
    in_process, in_process_cpu = {}, {}
    for mutant in (None, "velocity-ignored"):
        rate, sequences, found, per_cpu = sequences_per_cpu_second(mutant, args.frames)
        in_process[mutant], in_process_cpu[mutant] = sequences, per_cpu
        ten_k = BUDGET_FRAMES / rate
        print(f"  against {mutant or 'itself':18} {rate:8.0f} frames/s {sequences:6.1f} "
              f"sequences/s  10,000 frames in {ten_k:5.2f} s = "
              f"{ten_k / BUDGET_SECONDS:4.2f} x the 10 s budget  ({found} finding(s))")
    rows = [("through a co-simulator (python -m emulator --cosim, exec:, the reference in "
             "process)", False)]
    if args.snapshot:
        rows.append(("through a co-simulator restoring its first power-on (--cosim "
                     "--snapshot)", True))
    for title, snapshot in rows:
        print(title)
        for mutant in (None, "velocity-ignored"):
            rate, sequences, found, per_cpu = sequences_per_cpu_second(
                mutant, args.frames, cosim=True, snapshot=snapshot)
            print(f"  against {mutant or 'itself':18} {rate:8.0f} frames/s {sequences:6.1f} "
                  f"sequences/s = {sequences / in_process[mutant]:4.2f} x in process  "
                  f"({found} finding(s)); per CPU second "
                  f"{per_cpu / in_process_cpu[mutant]:4.2f} x")


if __name__ == "__main__":
    main()
