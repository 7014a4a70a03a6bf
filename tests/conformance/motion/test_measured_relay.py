"""The measured family in real time behind a USB-serial-like relay (16 ms latency timer,
62-byte chunks, jitter): a correct unit gets no FAIL. Slow: prints the runs and FAILs."""

from __future__ import annotations

import os
import re
import time

import pytest

from conformance.link.framing import frame
from conformance.run.runner import run
from conformance.run.selection import select
from conformance.targets import parse_target
from conformance.verdicts.verdict import FAIL
from tests.emulator.process import Emulator
from tests.usb_relay import UsbRelay

REPEATS = int(os.environ.get("GVE_MEASURED_REPEATS", "20"))
BAND = re.compile(r"\(±([\d.]+) ms line, ±(\d+) steps?\)")


@pytest.mark.slow
@pytest.mark.pty
@pytest.mark.parametrize("latency_ms", [None, 16])
def test_measured_family_repeated_gets_no_fail(latency_ms: int | None) -> None:
    emu = Emulator("--model", "GVE84-100", "--pty")
    relay = UsbRelay(emu.first, latency_ms=latency_ms, jitter_ms=3) if latency_ms else None
    failed: dict[str, int] = {}
    bands: list[tuple[float, int]] = []
    try:
        path = relay.path if relay else emu.first
        for n in range(REPEATS):
            began = time.monotonic()
            target = parse_target(f"serial:{path}?baud=115200", profile="GVE84-100",
                                  allow_destructive=True, max_travel=100_000)
            for r in run([target], select(["10.*measured*"])).results:
                bands += [(float(m.group(1)), int(m.group(2))) for c in r.checks
                          if (m := BAND.search(c["what"]))]
                if r.verdict == FAIL:
                    failed[r.id] = failed.get(r.id, 0) + 1
            # each run as it ends: a long repeat cut short still tells what ran
            print(f"latency {latency_ms} ms, run {n + 1}: {time.monotonic() - began:.0f} s, "
                  f"load {os.getloadavg()[0]:.1f}; FAILs so far {failed}", flush=True)
    finally:
        if relay:
            relay.close()
        emu.stop()
    lines, steps = sorted(b[0] for b in bands), sorted(b[1] for b in bands)
    print(f"latency {latency_ms} ms: {REPEATS} runs, FAILs {failed}; line band median "
          f"±{lines[len(lines) // 2]:.1f} ms, widest ±{lines[-1]:.1f} ms; steps median "
          f"±{steps[len(steps) // 2]}, widest ±{steps[-1]}")
    assert bands and not failed


@pytest.mark.pty
def test_an_h_the_line_delivers_late_fails_no_measured_case() -> None:
    """The HALT cases behind a line that delivers each H 40 ms late (the host under load as
    it sent it, which no round trip before it shows): the unit brakes from farther on, and
    its answer comes as much later; the readings after it are judged with how late that
    answer shows the H may have been taken. A correct unit fails no check."""
    emu = Emulator("--model", "GVE84-100", "--pty")
    relay = UsbRelay(emu.first, latency_ms=1, jitter_ms=0, hold=frame("H", 0, False),
                     hold_ms=40)
    try:
        target = parse_target(f"serial:{relay.path}?baud=115200", profile="GVE84-100",
                              allow_destructive=True, max_travel=100_000)
        results = run([target], select(["10.4.measured.*"])).results
        held = relay.held
    finally:
        relay.close()
        emu.stop()
    assert len(results) == 3 and held >= 3            # each case's H came late
    failed = {r.id: [c["what"] for c in r.checks if not c["ok"]] for r in results}
    assert not any(failed.values()), failed
