"""The stepper cores: pushes, position queries and pulse trains per second, per core,
and the cost of advancing through 2048 vectors of 2**31 steps (closed form).

    python -m bench.bench_stepper
"""

from __future__ import annotations

import time

from emulator.motion.factory import c_available, create
from emulator.motion.interface import Vector


def vectors(n: int, steps: int) -> list[Vector]:
    return [Vector((steps, -steps // 3, steps // 7, 0), True, 400_000, 10_000_000, 400_000,
                   512, 5_000_000, False, (500_000,) * 4) for _ in range(n)]


def measure(stepper: str) -> dict[str, float]:
    out: dict[str, float] = {}
    m = create(4, 500_000, stepper=stepper)
    vs = vectors(2048, 2**31 - 1)
    t0 = time.perf_counter()
    for i, v in enumerate(vs):
        m.push(v, i)
    out["pushes/s"] = len(vs) / (time.perf_counter() - t0)
    t0 = time.perf_counter()
    end = m.drain_instant()
    m.position(end)
    out["seconds to run out 2048 x 2**31 steps"] = time.perf_counter() - t0
    m = create(4, 500_000, stepper=stepper)
    for i, v in enumerate(vectors(64, 20_000)):
        m.push(v, i)
    end = m.drain_instant()
    t0 = time.perf_counter()
    n = 20_000
    probe = create(4, 500_000, stepper=stepper)
    for i, v in enumerate(vectors(64, 20_000)):
        probe.push(v, i)
    for k in range(n):
        probe.position(k * (end // n))
    out["position queries/s"] = n / (time.perf_counter() - t0)
    t0 = time.perf_counter()
    times, _ = m.pulses(0, end // 8)
    out["pulses/s (train)"] = len(times) / (time.perf_counter() - t0)
    return out


def main() -> None:
    cores = ["python"] + (["c"] if c_available() else [])
    results = {core: measure(core) for core in cores}
    for key in results["python"]:
        line = f"{key:40}" + "".join(f"{core}: {results[core][key]:>14,.3f}  " for core in cores)
        if len(cores) == 2 and results["python"][key] and results["c"][key]:
            py, c = results["python"][key], results["c"][key]
            speedup = py / c if key.startswith("seconds") else c / py   # rates vs durations
            line += f"C is {speedup:.1f}x the Python twin"
        print(line)
    if len(cores) == 1:
        print("(the C core is not built: only the Python twin was measured)")


if __name__ == "__main__":
    main()
