"""Clocks: virtual time moves only when told and never backwards; real time is monotonic
from the clock's creation."""

from __future__ import annotations

import time

from emulator.link.clock import RealClock, VirtualClock


def test_virtual_clock_moves_only_when_told() -> None:
    clock = VirtualClock()
    assert clock.now() == 0
    assert clock.now() == 0
    clock.advance_to(1_500)
    assert clock.now() == 1_500
    clock.advance_to(1_000)          # the past is not a place to go back to
    assert clock.now() == 1_500
    assert VirtualClock(origin=7).now() == 7


def test_real_clock_counts_from_its_creation() -> None:
    clock = RealClock()
    first = clock.now()
    assert 0 <= first < 1_000_000_000
    deadline = time.monotonic() + 1.0
    while clock.now() == first and time.monotonic() < deadline:
        pass
    assert clock.now() > first
    clock.advance_to(10**18)        # cannot be pushed
    assert clock.now() < 10**18
