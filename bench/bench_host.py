"""Host role benchmark: figures as ratios measured in one run.

1. The relay and an emulated GVE114-500 at 921 600 baud, fed a host's traffic as fast as
   it comes: the time the line itself needs for those bytes over the time the relay took
   (≥ 1: the host role keeps up with the line), and the same for the emulator alone
   behind its pyserial port. Two streams, every frame different: simplex exchanges (a
   setting or a vector, its answer) and packets of 50 members (no answers) and `*E`.
   Reading the frames and booking the units' views waits until after the run
   (host/booking.py): its time is printed beside, not counted against the line.
2. A full certification of the reference host on one profile against the budget
   "the job's time × (scenarios + 1) + 10 %" (≥ 1: within budget).

    python -m bench.bench_host [--profile GVE84-100] [--members 2000] [--no-certify]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import gve_host
from conformance.host.certify import Plan, certify
from conformance.host.line_faults import Fault
from conformance.host.played_units import load_units, open_line
from conformance.host.ports.silent import SilentPort
from conformance.host.relay import Relay
from conformance.host.scenarios import SCENARIOS
from conformance.host.unitview import line_views

BAUD = 921_600
JOB = Path(gve_host.__file__).parent / "jobs" / "square.job"


def stream(kind: str, n: int) -> tuple[list[bytes], int]:
    """Frames of a host's traffic and the bytes the line carries for them (frames, and
    the answers of the frames that get one: `0\\r` or `0,k\\r`)."""
    if kind == "exchanges":
        # every frame different (the relay caches nothing for them)
        frames = [b"!0V%d\r" % (10000 + i) if i % 2 else b"!0C%d,-%d,0\r" % (i + 1, i % 7)
                  for i in range(n)]
        return frames, sum(len(f) for f in frames) + 2 * n
    frames, answers, size = [], 0, 50
    for start in range(0, n, size):
        k = min(size, n - start)
        frames += [b"!0*S\r", *(b"!0C%d,0,0\r" % (start + i + 1) for i in range(k)),
                   b"!0*E%d\r" % k]
        answers += len(b"0,%d\r" % k)
    return frames, sum(len(f) for f in frames) + answers


def relay_ratio(kind: str, n: int) -> tuple[float, float, float]:
    """(line time / relay time, relay seconds, seconds to judge after the run) for ``n``
    frames of ``kind``."""
    units = load_units(["GVE114-500"])
    line = open_line(units, BAUD)
    port = SilentPort()
    relay = Relay(port, line, line_views(units), Fault(), BAUD)
    frames, carried = stream(kind, n)
    start = time.perf_counter()
    for frame in frames:                   # a simplex host: one frame, then its answer
        relay.take_host(frame, time.monotonic_ns())
        relay.deliver()
    took = time.perf_counter() - start
    start = time.perf_counter()
    relay.booking.settle()
    after = time.perf_counter() - start
    line.close()
    port.close()
    answered = sum(1 for ex in relay.rec.exchanges if ex.answer)
    expected = n if kind == "exchanges" else sum(f.startswith(b"!0*E") for f in frames)
    if answered != expected:
        print(f"  ({kind}: {expected - answered} answer(s) went missing)")
    return carried * 10 / BAUD / took, took, after


def emulator_ratio(kind: str, n: int) -> float:
    """The same stream through the emulator alone (its pyserial port, no relay)."""
    units = load_units(["GVE114-500"])
    line = open_line(units, BAUD)
    frames, carried = stream(kind, n)
    byte = 10 / BAUD
    start = time.perf_counter()
    for frame in frames:
        line.write(frame)
        line.timeout = 2 * byte
        if line.read(1):
            line.timeout = 64 * byte
            line.read_until(b"\r")
    took = time.perf_counter() - start
    line.close()
    return carried * byte / took


def certification(profile: str) -> None:
    command = [sys.executable, "-m", "gve_host", "{port}", "--job", str(JOB), "--checksums",
               "--packets", "4"]
    units = load_units([profile])
    plan = Plan(units, units[0][0].default_baud, list(SCENARIOS), command)
    run = certify(plan, "bench", lambda r: None)
    clean = next(r for r in run.results if r.scenario == "clean")
    budget = clean.seconds * (len(SCENARIOS) + 1) * 1.1
    verdicts = {r.verdict for r in run.results}
    print(f"full certification of the reference host on {profile}: {run.seconds:.1f} s for "
          f"{len(SCENARIOS)} scenarios; the job takes {clean.seconds:.2f} s, budget "
          f"{budget:.1f} s -> budget / actual = {budget / run.seconds:.2f} "
          f"(verdicts: {', '.join(sorted(verdicts))})")


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(prog="python -m bench.bench_host",
                                 description=__doc__.splitlines()[0])
    ap.add_argument("--profile", default="GVE84-100")
    ap.add_argument("--members", type=int, default=2000)
    ap.add_argument("--no-certify", action="store_true")
    args = ap.parse_args(argv)
    print(f"host role at {BAUD} baud (GVE114-500), line time / relay time (>= 1 keeps up):")
    for kind in ("exchanges", "packets"):
        ratio, took, after = relay_ratio(kind, args.members)
        alone = emulator_ratio(kind, args.members)
        print(f"  {kind:10} {args.members} frames in {took:.2f} s: relay and units {ratio:.2f}"
              f" (the emulator alone {alone:.2f}; read and booked after the run in "
              f"{after:.2f} s)")
    if not args.no_certify:
        certification(args.profile)


if __name__ == "__main__":
    main()
