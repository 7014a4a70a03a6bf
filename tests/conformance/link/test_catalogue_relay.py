"""The whole catalogue against the emulator behind a USB-serial-like relay (16 ms latency
timer, 62-byte chunks, jitter): a correct unit gets no FAIL and no ERROR. Slow; repeated
GVE_CATALOGUE_REPEATS times (default 1); prints the runs, their time and the line's band
the measured checks used."""

from __future__ import annotations

import os
import re
import time

import pytest

from conformance.run.runner import run
from conformance.run.selection import select
from conformance.targets import parse_target
from conformance.verdicts.verdict import ERROR, FAIL
from tests.emulator.process import Emulator
from tests.usb_relay import UsbRelay

REPEATS = int(os.environ.get("GVE_CATALOGUE_REPEATS", "1"))
BAND = re.compile(r"\(±([\d.]+) ms line, ±(\d+) steps?\)")


@pytest.mark.slow
@pytest.mark.pty
def test_the_catalogue_behind_a_16_ms_relay_gets_no_fail() -> None:
    emu = Emulator("--model", "GVE84-100", "--pty")
    relay = UsbRelay(emu.first, latency_ms=16, jitter_ms=3)
    failed: dict[str, list[str]] = {}
    lines: list[float] = []
    ran = 0
    start = time.monotonic()
    try:
        for n in range(REPEATS):
            began = time.monotonic()
            target = parse_target(f"serial:{relay.path}?baud=115200", profile="GVE84-100",
                                  allow_destructive=True, max_travel=100_000)
            results = run([target], select(None)).results
            ran = len(results)
            for r in results:
                lines += [float(m.group(1)) for c in r.checks
                          if (m := BAND.search(c["what"]))]
                if r.verdict in (FAIL, ERROR):
                    failed.setdefault(r.id, []).append(
                        next((c["what"] for c in r.checks if not c["ok"]), r.verdict))
            # each run as it ends: a long repeat cut short still tells what ran
            print(f"run {n + 1}: {ran} cases in {time.monotonic() - began:.0f} s, load "
                  f"{os.getloadavg()[0]:.1f}; FAIL/ERROR so far {failed}", flush=True)
    finally:
        relay.close()
        emu.stop()
    lines.sort()
    print(f"16 ms relay: {REPEATS} run(s) of {ran} cases in {time.monotonic() - start:.0f} s; "
          f"line band median ±{lines[len(lines) // 2]:.1f} ms, widest ±{lines[-1]:.1f} ms; "
          f"FAIL/ERROR {failed}")
    assert ran and lines
    assert not failed
