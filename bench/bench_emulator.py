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
import statistics
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


def in_process(seconds: float, windows: int = 6) -> tuple[float, float]:
    """The mix per second through ``gve://`` and through ``loop://``, in alternating
    windows; the median window of each."""
    emu = serial.serial_for_url("gve://?model=GVE84-100", timeout=1)
    loop = serial.serial_for_url("loop://", timeout=1)
    rates: tuple[list[float], list[float]] = ([], [])
    for _ in range(windows):
        rates[0].append(frames_per_second(emu, seconds / windows,
                                          lambda: emu.line.run_until_idle(3600)))
        rates[1].append(frames_per_second(loop, seconds / windows))
    return statistics.median(rates[0]), statistics.median(rates[1])


def round_trips(commands: dict[str, list[str]], seconds: float,
                windows: int = 6) -> dict[str, float]:
    """``!0V1000`` round trips per second against each server, measured in alternating
    windows (so that a change of the machine's load falls on all of them alike); the
    median window of each."""
    procs: dict[str, subprocess.Popen] = {}
    ports: dict[str, serial.Serial] = {}
    rates: dict[str, list[float]] = {name: [] for name in commands}
    try:
        for name, command in commands.items():
            procs[name] = proc = subprocess.Popen(command, stdin=subprocess.PIPE,
                                                  stdout=subprocess.PIPE, text=True)
            ports[name] = serial.Serial(proc.stdout.readline().split()[-1], 115200, timeout=2)
        for _ in range(windows):
            for name, port in ports.items():
                n, start = 0, time.perf_counter()
                while time.perf_counter() - start < seconds / windows:
                    port.write(b"!0V1000\r")
                    port.read_until(b"\r")
                    n += 1
                rates[name].append(n / (time.perf_counter() - start))
    finally:
        for port in ports.values():
            port.close()
        for proc in procs.values():
            proc.terminate()
            proc.wait(10)
    return {name: statistics.median(r) for name, r in rates.items()}


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seconds", type=float, default=3.0)
    ap.add_argument("--no-profile", dest="profile", action="store_false",
                    help="skip the cProfile run of the in-process loop (top items by own time)")
    args = ap.parse_args(argv)
    s = args.seconds
    emu, loop = in_process(2 * s)
    print(f"in process (virtual time): {emu:,.0f} commands/s; loop:// {loop:,.0f}/s; "
          f"share {emu / loop:.0%} (goal {GOAL_IN_PROCESS:.0%})")
    here = [sys.executable, "-m"]
    rt = round_trips({"emulator": [*here, "emulator", "--model", "GVE84-100", "--pty"],
                      "echo": [*here, "bench.pty_echo"],
                      "answer": [*here, "bench.pty_echo", "--answer"]}, 3 * s)
    emu_pty, echo, answer = rt["emulator"], rt["echo"], rt["answer"]
    print(f"over a pty (real time):    {emu_pty:,.0f} round trips/s; bare pty echo server "
          f"{echo:,.0f}/s; share {emu_pty / echo:.0%} (goal {GOAL_PTY:.0%})")
    print(f"                           bare server answering 0 {answer:,.0f}/s; "
          f"share {emu_pty / answer:.0%} (the emulator's own work, for reference)")
    if args.profile:
        prof = cProfile.Profile()
        port = serial.serial_for_url("gve://?model=GVE84-100", timeout=1)
        prof.enable()
        frames_per_second(port, s / 2, lambda: port.line.run_until_idle(3600))
        prof.disable()
        out = io.StringIO()
        pstats.Stats(prof, stream=out).sort_stats("tottime").print_stats(15)
        print(out.getvalue())


if __name__ == "__main__":
    main()
