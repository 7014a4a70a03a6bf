"""Clocks in integer nanoseconds: virtual (moves only when told) and real (monotonic)."""

from __future__ import annotations

import time


class VirtualClock:
    virtual = True

    def __init__(self, origin: int = 0) -> None:
        self._now = origin

    def now(self) -> int:
        return self._now

    def advance_to(self, t: int) -> None:
        if t > self._now:
            self._now = t


class RealClock:
    virtual = False

    def __init__(self) -> None:
        self._origin = time.monotonic_ns()

    def now(self) -> int:
        return time.monotonic_ns() - self._origin

    def advance_to(self, t: int) -> None:
        """Real time cannot be pushed: callers wait for it themselves."""
