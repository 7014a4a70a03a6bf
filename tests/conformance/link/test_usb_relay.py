"""The USB-serial-like relay the real-time tests put between the suite and the emulator:
every answer comes no sooner than the latency timer, whole, and in time."""

from __future__ import annotations

import time

import pytest
import serial

from conformance.link.framing import frame
from tests.emulator.process import Emulator
from tests.usb_relay import UsbRelay

pytestmark = pytest.mark.pty


@pytest.mark.parametrize("latency_ms", [1, 16])
def test_answers_wait_for_the_latency_timer(latency_ms: int) -> None:
    emu = Emulator("--model", "GVE84-100", "--pty")
    relay = UsbRelay(emu.first, latency_ms=latency_ms, jitter_ms=2)
    try:
        with serial.Serial(relay.path, 115200, timeout=1.0) as port:
            trips = []
            for _ in range(5):
                start = time.monotonic()
                port.write(frame("?", 0, False))
                answer = port.read_until(b"\r")
                trips.append(time.monotonic() - start)
                assert answer.startswith(b"0,") and answer.endswith(b"\r"), answer
    finally:
        relay.close()
        emu.stop()
    assert min(trips) >= latency_ms / 1e3, trips
    assert max(trips) < latency_ms / 1e3 + 0.5, trips
