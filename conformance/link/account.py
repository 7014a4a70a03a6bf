"""Where a run's time went: the time account of one session (docs/suite.md, "Where the
time goes").

Every link of a session books what it waited for, measured on its own clock (real or
virtual), under one of the :class:`Spent` heads: the bytes at the baud rate, the unit's
time to answer beyond them, the motion the unit had to perform, the waits the manual
requires (a restart, the watchdog), a technician's steps, and the suite's own waits
(for answers that do not come, a quiet line, margins). What the bookings do not cover
of the session's wall time is the suite's own work between exchanges. In virtual time
nothing but the bookings moves the clock, so they sum to the clock's time.
"""

from __future__ import annotations

import enum
import time
from collections.abc import Callable


class Spent(enum.StrEnum):
    """What an interval of a run went to, in the order the account lists them."""

    LINE = "line"              # the bytes at the baud rate
    ANSWERS = "answers"        # the unit's time to answer beyond its bytes, the line's latency
    MOTION = "motion"          # the unit moving: answers at a motion's end, waits while it moves
    MANUAL = "manual waits"    # what the manual requires: a restart, the watchdog
    HANDS = "hands"            # a technician's steps
    WAITS = "suite waits"      # the suite's own: answers that do not come, quiet, margins
    WORK = "suite work"        # the suite's own processing between exchanges


#: the heads that are the suite's own share of a run
SUITE = (Spent.WAITS, Spent.WORK)


class TimeAccount:
    """The bookings of one session, and its wall time: real time from :meth:`begin` to
    :meth:`end`, or in virtual time the clock's time on each link (every embedded
    emulator's link is a fresh unit with a clock of its own)."""

    def __init__(self, clock: Callable[[], float] = time.monotonic) -> None:
        self._clock = clock
        self.booked: dict[Spent, float] = dict.fromkeys(Spent, 0.0)
        self._began: float | None = None
        self._ended: float | None = None
        self._virtual = 0.0                      # closed links' virtual time
        self._link_now: Callable[[], float] | None = None

    def begin(self) -> None:
        if self._began is None:
            self._began = self._clock()

    def end(self) -> None:
        self._ended = self._clock()
        self.follow(None)

    def follow(self, seconds: Callable[[], float] | None) -> None:
        """Virtual time: from now on the clock of a new link (its seconds since it
        began); the last one's time is kept."""
        if self._link_now is not None:
            self._virtual += self._link_now()
        self._link_now = seconds

    def book(self, spent: Spent, seconds: float) -> None:
        if seconds > 0:
            self.booked[spent] += seconds

    @property
    def virtual(self) -> bool:
        return self._link_now is not None or self._virtual > 0

    def wall(self) -> float:
        """The session's time: its virtual clocks' in virtual time, else real time."""
        if self.virtual:
            return self._virtual + (self._link_now() if self._link_now else 0.0)
        if self._began is None:
            return 0.0
        return (self._ended if self._ended is not None else self._clock()) - self._began

    def totals(self) -> dict[str, float]:
        """Seconds per head, :attr:`Spent.WORK` being what the bookings leave of the wall
        time; ``wall`` the whole."""
        wall = self.wall()
        shown = {str(k): round(v, 3) for k, v in self.booked.items() if k != Spent.WORK}
        shown[str(Spent.WORK)] = round(max(0.0, wall - sum(self.booked.values())), 3)
        shown["wall"] = round(wall, 3)
        return shown


def suite_share(totals: dict[str, float]) -> float:
    """The suite's own waits and work as a share of the wall time (0..1)."""
    wall = totals.get("wall", 0.0)
    return sum(totals.get(str(s), 0.0) for s in SUITE) / wall if wall else 0.0


def account_lines(totals: dict[str, float]) -> list[str]:
    """The account as the console's last lines print it: the wall time, then each head
    with its share, the suite's own share last."""
    wall = totals.get("wall", 0.0)
    if not wall:
        return []
    parts = [f"{name} {totals[str(name)]:.1f} s ({100 * totals[str(name)] / wall:.0f} %)"
             for name in Spent if totals.get(str(name))]
    return [f"time: {wall:.1f} s = " + ", ".join(parts),
            f"  the suite's own waits and work: {100 * suite_share(totals):.0f} % of it"]
