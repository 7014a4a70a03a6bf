"""The stepper cores: pushes, queries and pulse trains per second, per core, and the
cost of advancing through 2048 vectors of 2**31 steps (closed form); the C core's rate
as a multiple of its Python twin's; and the C core's pulse train against a plain exact
kernel that computes the same train (one vector's steps in order: Bresenham over the
axes, an integer recurrence for the instants; built with the core:
emulator/motion/_kernel.c), as a fraction of the kernel's rate, the two trains checked
identical first.

Everything is measured in this one run: each figure is the best of a few timed runs,
and the subjects of one figure (the two cores; the C core and the kernel) are timed
in turns, so that a machine that slows down or speeds up meanwhile moves both alike.

    python -m bench.bench_stepper [--repeats N]
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from emulator.motion.factory import c_available, create
from emulator.motion.interface import Motion, Vector

AXES, MAX_RATE = 4, 500_000
#: the vector of the one-vector trains: an L from rest to rest, with its cruise rate the
#: V (below every axis limit) and no dwell, so that its plan is the reference's own; the
#: C core and the kernel run a train ten times as long (each timed run some 30 ms)
TRAIN_STEPS = (100_000, -33_333, 14_285, 0)
KERNEL_STEPS = tuple(10 * d for d in TRAIN_STEPS)
TRAIN_V, TRAIN_A = 400_000, 10_000_000
#: queries at this many instants spread over 64 vectors, as a unit's status answers ask
#: (queued and next_event are left out: a counter read costs one call in either core)
QUERIES = 20_000
QUERIED = ("position", "physical", "excursion", "flags")


def vectors(n: int, steps: int) -> list[Vector]:
    return [Vector((steps, -steps // 3, steps // 7, 0), True, 400_000, 10_000_000, 400_000,
                   512, 5_000_000, False, (500_000,) * 4) for _ in range(n)]


def train_vector(steps: tuple[int, ...] = TRAIN_STEPS) -> Vector:
    return Vector(steps, False, TRAIN_V, TRAIN_A, TRAIN_V, 0, 0, False, (MAX_RATE,) * AXES)


def loaded(stepper: str, n: int, steps: int) -> Motion:
    m = create(AXES, MAX_RATE, stepper=stepper)
    for i, v in enumerate(vectors(n, steps)):
        m.push(v, i)
    return m


@dataclass
class Timed:
    """One subject of a figure: ``run`` is timed on a fresh ``prepare()`` (untimed);
    the figure is ``count`` per second of the fastest run (or its seconds when
    ``count`` is None)."""

    prepare: Callable[[], object]
    run: Callable[[object], object]
    count: int | None

    def once(self) -> float:
        subject = self.prepare()
        t0 = time.perf_counter()
        self.run(subject)
        return time.perf_counter() - t0


def in_turns(repeats: int, subjects: dict[str, Timed]) -> dict[str, float]:
    """Every subject's figure, their runs taken in turns."""
    fastest = dict.fromkeys(subjects, float("inf"))
    for _ in range(repeats):
        for name, subject in subjects.items():
            fastest[name] = min(fastest[name], subject.once())
    return {name: fastest[name] if s.count is None else s.count / fastest[name]
            for name, s in subjects.items()}


def figures(stepper: str) -> dict[str, Timed]:
    """What is timed of a core, by the figure's name."""
    out: dict[str, Timed] = {}
    vs = vectors(2048, 2**31 - 1)

    def push_all(m: Motion) -> None:
        for i, v in enumerate(vs):
            m.push(v, i)

    out["pushes/s"] = Timed(lambda: create(AXES, MAX_RATE, stepper=stepper), push_all,
                            len(vs))
    out["seconds to run out 2048 x 2**31 steps"] = Timed(
        lambda: loaded(stepper, 2048, 2**31 - 1), lambda m: m.position(m.drain_instant()),
        None)
    end = loaded(stepper, 64, 20_000).drain_instant()
    instants = [k * (end // QUERIES) for k in range(QUERIES)]
    for name in QUERIED:
        def query(m: Motion, name: str = name) -> None:
            ask = getattr(m, name)
            for t in instants:
                ask(t)
        out[f"{name} queries/s"] = Timed(lambda: loaded(stepper, 64, 20_000), query, QUERIES)
    train = loaded(stepper, 64, 20_000)
    out["pulses/s (train of 8 C vectors)"] = Timed(
        lambda: train, lambda m: m.pulses(0, end // 8), len(train.pulses(0, end // 8)[0]))
    single, until = one_vector(stepper)
    out["pulses/s (one L vector)"] = Timed(lambda: single, lambda m: m.pulses(0, until),
                                           len(single.pulses(0, until)[0]))
    return out


def one_vector(stepper: str, steps: tuple[int, ...] = TRAIN_STEPS) -> tuple[Motion, int]:
    """A core holding a one-vector train's vector, and the end of its train."""
    m = create(AXES, MAX_RATE, stepper=stepper)
    m.push(train_vector(steps), 0)
    return m, m.drain_instant() + 1


def against_kernel(repeats: int) -> tuple[float, float, bool]:
    """Pulses per second of the plain kernel and of the C core for the kernel's train
    (twice as many runs as a figure, in turns), and whether the two trains are the same
    (instants and masks)."""
    from emulator.motion.kernel import kernel_pulses

    def plain(_: object = None) -> tuple[np.ndarray, np.ndarray]:
        return kernel_pulses(KERNEL_STEPS, 0, TRAIN_V, TRAIN_A)

    core, until = one_vector("c", KERNEL_STEPS)
    train = core.pulses(0, until)
    same = all(np.array_equal(a, b) for a, b in zip(plain(), train, strict=True))
    rates = in_turns(2 * repeats, {"kernel": Timed(lambda: None, plain, len(train[0])),
                                   "core": Timed(lambda: core, lambda m: m.pulses(0, until),
                                                 len(train[0]))})
    return rates["kernel"], rates["core"], same


def positive(text: str) -> int:
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"{text}: must be at least 1")
    return value


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(prog="python -m bench.bench_stepper")
    parser.add_argument("--repeats", type=positive, default=5,
                        help="timed runs per figure and subject, the best counts (default 5)")
    args = parser.parse_args(argv)
    cores = ["python"] + (["c"] if c_available() else [])
    subjects = {core: figures(core) for core in cores}
    for key in subjects["python"]:
        result = in_turns(args.repeats, {core: subjects[core][key] for core in cores})
        line = f"{key:40}" + "".join(f"{core}: {result[core]:>14,.3f}  " for core in cores)
        if len(cores) == 2 and result["python"] and result["c"]:
            py, c = result["python"], result["c"]
            speedup = py / c if subjects["c"][key].count is None else c / py
            line += f"C is {speedup:.1f}x the Python twin"
        print(line, flush=True)
    if len(cores) == 1:
        print("(the C core is not built: only the Python twin was measured)")
        return
    kernel, core, same = against_kernel(args.repeats)
    line = f"{'pulses/s (10x that vector), plain kernel':41}c: {kernel:>14,.3f}  "
    if same:
        line += f"the C core ({core:,.0f}/s, in turns with it) is {core / kernel:.0%} of it"
    else:
        line += "the C core's train differs from it: no ratio"
    print(line)


if __name__ == "__main__":
    main()
