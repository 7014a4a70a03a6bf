"""The differential fuzzer in process: the emulator against a mutant of itself (and against
itself), frames per second with the search's own overhead (drawing, shrinking), and the
time 10,000 frames take as a ratio of a 10 s budget (below 1: met); then the same search
through a co-simulator (`exec:` of `python -m emulator --cosim`, docs/cosim.md: virtual
time over the text protocol, each sequence begun at the simulator's power-on through its
rig, judged by the project's arithmetic as in process: --strict), its sequences per
second and their ratio to the in-process figure; and the same ratio per CPU second (this
process's and the simulator's): on a loaded machine the two processes take turns and the
wall-clock ratio falls towards it, on an idle one the simulator runs beside the suite
(and stays awake for the suite's next command, emulator/link/awake.py: processor time
the per-CPU figure counts).
Both sides run the same searches (the same seeds, as many as the in-process run took to
send the frames), so the ratio compares the same sequences and frames; the line says so,
or how they differ.

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
from dataclasses import dataclass

from conformance.diff.engine import Budget, Pair, search
from conformance.diff.grammar import Options
from conformance.diff.sides import Side
from conformance.link.liveness import TargetNotResponding
from conformance.link.signals import StopSignals
from conformance.targets import parse_target

BUDGET_FRAMES = 10_000
BUDGET_SECONDS = 10.0
#: the motion envelope through a co-simulator (--max-travel): its searches' longest moves
MAX_TRAVEL = 20_000


def cosim_spec(mutant: str | None, *, snapshot: bool = False) -> str:
    return "exec:" + shlex.join([sys.executable, "-m", "emulator", "--model", "GVE84-100",
                                 "--cosim", *(["--snapshot"] if snapshot else []),
                                 *(["--mutant", mutant] if mutant else [])])


@dataclass
class Run:
    """What a run of searches did."""

    frames: int
    sequences: int
    seconds: float
    found: int
    searches: int          # searches of SEARCH sequences run (seeds 0, SEARCH, ...)

    @property
    def rate(self) -> float:
        return self.frames / self.seconds

    @property
    def sequences_per_second(self) -> float:
        return self.sequences / self.seconds


def frames_per_second(mutant: str | None, frames: int, *, cosim: bool = False,
                      snapshot: bool = False, searches: int | None = None) -> Run:
    """Searches that send ``frames`` frames (or the first ``searches`` of them, the same
    seeds); ``snapshot``: through a co-simulator that restores its first power-on. Both
    sides count the run's stop signals under its handler, as `gve-conformance diff` runs
    them (a write asks a flag; without the handler each write swaps the handlers)."""
    reference = parse_target("emu:GVE84-100")
    interrupts = StopSignals()
    if cosim:
        # the envelope docs/cosim.md gives for the long moves; judged as in process, by
        # the project's arithmetic (--strict: the emulator claims it), so both rows
        # compare the same way (exact placement, no other reading of the motion watched)
        target = parse_target(cosim_spec(mutant, snapshot=snapshot), profile="GVE84-100",
                              allow_destructive=True, max_travel=MAX_TRAVEL, strict=True)
        target.preflight()
    else:
        target = parse_target("emu:GVE84-100" + (f"?mutant={mutant}" if mutant else ""))
    pair = Pair(Side(target, target.begin(interrupts)),
                Side(reference, reference.begin(interrupts)), target.profile)
    pair.restores = snapshot
    try:
        with interrupts.catching():
            return _search(pair, frames, searches)
    finally:
        if cosim:
            target.session.finish()
            target.close()


def _cpu_seconds() -> float:
    """CPU seconds this process and its ended children (a simulator, once closed) used."""
    return sum(u.ru_utime + u.ru_stime for u in (resource.getrusage(resource.RUSAGE_SELF),
                                                 resource.getrusage(resource.RUSAGE_CHILDREN)))


def sequences_per_cpu_second(mutant: str | None, frames: int, *, cosim: bool = False,
                             snapshot: bool = False, searches: int | None = None
                             ) -> tuple[Run, float]:
    """:func:`frames_per_second`, and the sequences per CPU second of this process and the
    simulator's."""
    cpu, began = _cpu_seconds(), time.perf_counter()
    run = frames_per_second(mutant, frames, cosim=cosim, snapshot=snapshot,
                            searches=searches)
    wall, cpu = time.perf_counter() - began, _cpu_seconds() - cpu
    return run, run.sequences_per_second * wall / cpu


#: sequences a search may run (a run's is one of 2000)
SEARCH = 500


def _search(pair: Pair, frames: int, searches: int | None = None) -> Run:
    budget = Budget(examples=None)
    found = done = 0
    # searches of SEARCH sequences until the frames are sent (or ``searches`` of them),
    # search k from the seed k * SEARCH whatever the searches before found, the probes
    # before the first only (a run sends them once); a finding ends one search, the
    # next goes on
    while (budget.frames < frames) if searches is None else done < searches:
        sent = budget.frames
        budget.examples = budget.used + SEARCH
        try:
            found += len(search(pair, Options(destructive=True, rig=True), budget,
                                seed=done * SEARCH, with_probes=done == 0))
        except TargetNotResponding as err:
            # a finding of diff's (or the suite's own misjudgement): the figures are over
            # what ran, and the line says so
            print(f"  (the search stopped after {budget.frames} frames: {err})", flush=True)
            break
        done += 1
        if budget.frames == sent:
            break               # a target that stopped responding sends no more
    return Run(budget.frames, budget.used, budget.elapsed, found, done)


def _alike(run: Run, other: Run) -> str:
    """Whether two runs of the same searches ran the same sequences and frames."""
    if (run.sequences, run.frames) == (other.sequences, other.frames):
        return f"the same {run.sequences} sequences, {run.frames} frames"
    return (f"{run.sequences} sequences, {run.frames} frames; in process "
            f"{other.sequences}, {other.frames}")


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(prog="bench_diff")
    ap.add_argument("--frames", type=int, default=BUDGET_FRAMES)
    ap.add_argument("--snapshot", action="store_true",
                    help="a row more: the co-simulator restoring its first power-on")
    args = ap.parse_args(argv)
    print("differential fuzzer, in process (GVE84-100, virtual time on both sides)")
    in_process: dict[str | None, Run] = {}
    in_process_cpu: dict[str | None, float] = {}
    for mutant in (None, "velocity-ignored"):
        run, per_cpu = sequences_per_cpu_second(mutant, args.frames)
        in_process[mutant], in_process_cpu[mutant] = run, per_cpu
        ten_k = BUDGET_FRAMES / run.rate
        print(f"  against {mutant or 'itself':18} {run.rate:8.0f} frames/s "
              f"{run.sequences_per_second:6.1f} sequences/s  10,000 frames in {ten_k:5.2f} s "
              f"= {ten_k / BUDGET_SECONDS:4.2f} x the 10 s budget  ({run.found} finding(s), "
              f"{run.searches} searches)")
    rows = [("through a co-simulator (python -m emulator --cosim, exec:, the reference in "
             "process)", False)]
    if args.snapshot:
        rows.append(("through a co-simulator restoring its first power-on (--cosim "
                     "--snapshot)", True))
    for title, snapshot in rows:
        print(title)
        for mutant in (None, "velocity-ignored"):
            base = in_process[mutant]
            run, per_cpu = sequences_per_cpu_second(mutant, args.frames, cosim=True,
                                                    snapshot=snapshot,
                                                    searches=base.searches)
            ratio = run.sequences_per_second / base.sequences_per_second
            print(f"  against {mutant or 'itself':18} {run.rate:8.0f} frames/s "
                  f"{run.sequences_per_second:6.1f} sequences/s = {ratio:4.2f} x in process "
                  f"({run.found} finding(s); {_alike(run, base)}); per CPU second "
                  f"{per_cpu / in_process_cpu[mutant]:4.2f} x")


if __name__ == "__main__":
    main()
