"""Whether the co-simulation server stays awake for its driver's next command, and how long
(the technique of a hypervisor's halt polling).

A process that sleeps on its input is woken late: tens of microseconds each time on a
virtual machine, paid by the driver at every command it writes. A server that polls its
input for a while after its replies went out is there at once, but holds a processor
meanwhile. So it stays awake only while the machine has a processor to spare: the
processor time the machine left idle (Linux: ``/proc/stat``) and the time the server
itself spent awake, over the last :data:`EVERY` seconds, at least :data:`SPARE`
processors. On a loaded machine (a test run's other workers, a busy process) it sleeps
at once, as it always did; where the idle time cannot be read, too.
"""

from __future__ import annotations

import contextlib
import os
import select
import time
from collections.abc import Callable

#: the longest the server stays awake for the next command (a driver in a hurry, a
#: differential search, mostly sends it within that)
SECONDS = 500e-6
#: how often the spare processor time is read again
EVERY = 0.1
#: the processors to spare (idle, or this server's awake time) to stay awake
SPARE = 0.5
#: a turn awake this long means another process took the processor: asleep from then on
SHARED = 50e-6
_TICKS = os.sysconf("SC_CLK_TCK") if hasattr(os, "sysconf") else 100


def idle_seconds() -> float | None:
    """The processor seconds the machine has left idle since it started, all processors
    together (Linux: ``/proc/stat``); None where that cannot be read."""
    with contextlib.suppress(OSError, ValueError, IndexError):
        with open("/proc/stat", "rb") as stat:
            fields = stat.readline().split()
        if fields[0] == b"cpu":
            return (int(fields[4]) + int(fields[5])) / _TICKS      # idle, waiting on I/O
    return None


class Awake:
    """How long the server stays awake for the next command (:attr:`window`), told how
    long each wait was (:meth:`waited`)."""

    def __init__(self, idle: Callable[[], float | None] = idle_seconds,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self.idle = idle
        self.clock = clock
        self.window = 0.0                    # asleep at once until the machine is read
        self._since = clock()
        self._idle_then = idle()
        self._awake = 0.0                    # seconds spent awake since then

    def until_readable(self, fd: int) -> None:
        """Poll ``fd`` for up to the window, yielding the processor at each turn, and
        stop at the first turn on which another process took it; then :meth:`waited`."""
        began = last = time.perf_counter()
        until = began + self.window
        while last < until and not select.select([fd], [], [], 0)[0]:
            os.sched_yield()
            now = time.perf_counter()
            if now - last > SHARED:
                break
            last = now
        self.waited(last - began)

    def waited(self, awake: float) -> None:
        """A wait is over, ``awake`` seconds of it spent awake; every :data:`EVERY`
        seconds the window opens (:data:`SECONDS`) or closes (0) on the spare
        processors."""
        self._awake += awake
        now = self.clock()
        span = now - self._since
        if span < EVERY:
            return
        idle = self.idle()
        spare = (None if idle is None or self._idle_then is None
                 else (idle - self._idle_then + self._awake) / span)
        self.window = SECONDS if spare is not None and spare >= SPARE else 0.0
        self._since, self._idle_then, self._awake = now, idle, 0.0
