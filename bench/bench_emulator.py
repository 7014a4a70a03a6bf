"""The emulator's speed as its share of a bare baseline, measured in one run:

- in process (virtual time): the frame mix against ``gve://`` and the same loop against
  pyserial's ``loop://`` (which only hands the bytes back);
- over a pty (real time): ``!0V1000`` round trips against ``python -m emulator --pty``
  and against a bare pty echo server (bench/pty_echo.py: the frame comes back as it
  went, 8 bytes for the emulator's 2); for reference also against a bare server that
  answers ``0`` to every frame with no work behind it.

    python -m bench.bench_emulator [--seconds 3] [--no-profile]

The machine is shared and noisy, so only the ratios of one run mean anything; the goals
are in the printout. The profile at the end lists where the in-process time goes.
"""

from __future__ import annotations

import argparse
import cProfile
import io
import pstats
import subprocess
import sys
import time
from collections.abc import Callable

import serial

import emulator  # noqa: F401  (registers gve://)

MIX = [b"!0V1000\r", b"!0SR6\r", b"!0PF\r", b"!0@\r", b"!0A100\r", b"!0F\r", b"!0C10,0,0\r",
       b"!0T5\r"]
GOAL_IN_PROCESS = 0.50      # of loop://
GOAL_PTY = 0.80             # of the bare pty round trip


def frames_per_second(port: serial.SerialBase, seconds: float,
                      between: Callable[[], None] = lambda: None) -> float:
    n, start = 0, time.perf_counter()
    while time.perf_counter() - start < seconds:
        for frame in MIX:
            port.write(frame)
            port.read_until(b"\r")
        n += len(MIX)
        if n % 4000 < len(MIX):
            between()
    return n / (time.perf_counter() - start)


def in_process(seconds: float) -> float:
    port = serial.serial_for_url("gve://?model=GVE84-100", timeout=1)
    return frames_per_second(port, seconds, lambda: port.line.run_until_idle(3600))


def loopback(seconds: float) -> float:
    return frames_per_second(serial.serial_for_url("loop://", timeout=1), seconds)


def round_trips(command: list[str], seconds: float) -> float:
    proc = subprocess.Popen(command, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    try:
        path = proc.stdout.readline().split()[-1]
        port = serial.Serial(path, 115200, timeout=2)
        n, start = 0, time.perf_counter()
        while time.perf_counter() - start < seconds:
            port.write(b"!0V1000\r")
            port.read_until(b"\r")
            n += 1
        port.close()
        return n / (time.perf_counter() - start)
    finally:
        proc.terminate()
        proc.wait(10)


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seconds", type=float, default=3.0)
    ap.add_argument("--no-profile", dest="profile", action="store_false",
                    help="skip the cProfile run of the in-process loop (top items by own time)")
    args = ap.parse_args(argv)
    s = args.seconds
    emu, loop = in_process(s), loopback(s)
    print(f"in process (virtual time): {emu:,.0f} commands/s; loop:// {loop:,.0f}/s; "
          f"share {emu / loop:.0%} (goal {GOAL_IN_PROCESS:.0%})")
    here = [sys.executable, "-m"]
    emu_pty = round_trips([*here, "emulator", "--model", "GVE84-100", "--pty"], s)
    echo = round_trips([*here, "bench.pty_echo"], s)
    answer = round_trips([*here, "bench.pty_echo", "--answer"], s)
    print(f"over a pty (real time):    {emu_pty:,.0f} round trips/s; bare pty echo server "
          f"{echo:,.0f}/s; share {emu_pty / echo:.0%} (goal {GOAL_PTY:.0%})")
    print(f"                           bare server answering 0 {answer:,.0f}/s; "
          f"share {emu_pty / answer:.0%} (the emulator's own work, for reference)")
    if args.profile:
        prof = cProfile.Profile()
        prof.enable()
        in_process(s / 2)
        prof.disable()
        out = io.StringIO()
        pstats.Stats(prof, stream=out).sort_stats("tottime").print_stats(15)
        print(out.getvalue())


if __name__ == "__main__":
    main()
