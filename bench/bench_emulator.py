"""Commands per second in process (virtual time) and round trips per second over the pty.

    python -m bench.bench_emulator [--seconds 3] [--no-profile]

Prints its figures; the machine is shared and noisy, so compare ratios from one run.
"""

from __future__ import annotations

import argparse
import cProfile
import io
import pstats
import subprocess
import sys
import time

import serial

import emulator  # noqa: F401  (registers gve://)

MIX = [b"!0V1000\r", b"!0SR6\r", b"!0PF\r", b"!0@\r", b"!0A100\r", b"!0F\r", b"!0C10,0,0\r",
       b"!0T5\r"]


def in_process(seconds: float) -> tuple[int, float]:
    port = serial.serial_for_url("gve://?model=GVE84-100", timeout=1)
    n, start = 0, time.perf_counter()
    while time.perf_counter() - start < seconds:
        for frame in MIX:
            port.write(frame)
            port.read_until(b"\r")
        n += len(MIX)
        if n % 4000 < len(MIX):
            port.line.run_until_idle(3600)
    return n, time.perf_counter() - start


def over_pty(seconds: float) -> tuple[int, float]:
    proc = subprocess.Popen([sys.executable, "-m", "emulator", "--model", "GVE84-100", "--pty"],
                            stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, text=True)
    try:
        path = proc.stdout.readline().strip()
        port = serial.Serial(path, 115200, timeout=2)
        n, start = 0, time.perf_counter()
        while time.perf_counter() - start < seconds:
            port.write(b"!0V1000\r")
            port.read_until(b"\r")
            n += 1
        port.close()
        return n, time.perf_counter() - start
    finally:
        proc.terminate()
        proc.wait(10)


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seconds", type=float, default=3.0)
    ap.add_argument("--no-profile", dest="profile", action="store_false",
                    help="skip the cProfile run of the in-process loop (top items by own time)")
    args = ap.parse_args(argv)
    n, dt = in_process(args.seconds)
    print(f"in process (virtual time): {n / dt:,.0f} commands/s  (goal 50,000)")
    n, dt = over_pty(args.seconds)
    print(f"over the pty (real time):  {n / dt:,.0f} round trips/s  (goal 5,000)")
    if args.profile:
        prof = cProfile.Profile()
        prof.enable()
        in_process(args.seconds / 2)
        prof.disable()
        out = io.StringIO()
        pstats.Stats(prof, stream=out).sort_stats("tottime").print_stats(12)
        print(out.getvalue())


if __name__ == "__main__":
    main()
