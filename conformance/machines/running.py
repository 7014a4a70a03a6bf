"""How long the vectors a machine had the unit take may still run, for the run's time
account: a machine's wait while they may run is the unit's motion, as a case's wait while
its vectors run is; the rest, and a wait with nothing under way, the suite's own
(docs/decisions.md). Counted from the frames and their answers only: each vector taken
with INTA clear at the speed set, one ramp up and down at the acceleration for a start
from rest (a `C` behind a running one joins it without a stop); a unit slower than that
only makes more of a wait the suite's."""

from __future__ import annotations

from conformance.link.account import Spent
from conformance.link.framing import Response
from conformance.link.link import Link
from gve_fixtures.protocol import SECOND


class Running:
    def __init__(self, link: Link, speed: float, accel: float) -> None:
        self.link = link
        self.speed, self.accel = speed, accel      # pulses/s, pulses/s^2
        self._until = 0          # the link's clock (ns) until which they may run
        self._halted = 0         # ns: what H left of them, for G to resume

    def left(self) -> int:
        """Nanoseconds the vectors taken may still run."""
        return max(0, self._until - self.link.now)

    def took(self, steps: int, r: Response | None) -> None:
        """A vector of ``steps`` along its longest axis was sent and answered ``r``."""
        if r is None or not r.ok or r.inta:
            return
        left = self.left()
        seconds = steps / self.speed + (0 if left else self.speed / self.accel)
        self._until = self.link.now + left + round(seconds * SECOND)

    def halted(self) -> None:
        """`H` answered: the axes stand, what was left waits for `G`."""
        self._halted, self._until = self.left(), 0

    def resumed(self) -> None:
        """`G` taken: the halted vectors run again."""
        self._until = self.link.now + self._halted

    def dropped(self) -> None:
        """The halted vectors deleted (or kept away from the queue)."""
        self._halted = 0

    def at_rest(self) -> None:
        """The unit was seen with nothing moving."""
        self._until = 0

    def wait(self, seconds: float) -> None:
        """Let ``seconds`` pass: motion while the vectors taken may run, the rest the
        suite's own wait."""
        moving = min(seconds, self.left() / SECOND)
        if moving > 0:
            self.link.wait(moving, Spent.MOTION)
        if seconds > moving:
            self.link.wait(seconds - moving)
