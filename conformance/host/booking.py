"""The judge's reading of each frame and the units' views, kept from the wire when asked
(the host benchmark and the reports ask).

Reading a frame against the rules (frame_rules.py) and booking an exchange on the units'
views (unitview.py) take longer than a 921,600-baud line leaves the relay for a frame,
and the line needs neither: the relay only passes bytes, pairs answers with frames and
delivers them with their faults. So the relay notes, in its own order, what happened —
a frame came, an exchange was answered, a unit restarted — and the booking reads and
books them when someone asks: a fault that needs the count of accepted vectors, a
unit's checksum mode or open packet, an exchange's reading, or the end of the run. A
frame is read in the checksum mode its unit was in when the frame came, as it would have
been at once; the order is the relay's, so the books are the same.
"""

from __future__ import annotations

from collections import deque

from conformance.host.frame_rules import LineRules
from conformance.host.recording import Exchange
from conformance.host.unitview import UnitView, by_address, profiles_by_address

#: what the relay notes
FRAME, ANSWERED, POWER_ON = "frame", "answered", "power-on"


class Booking:
    def __init__(self, views: list[UnitView]) -> None:
        self.views = views
        self.view_at = by_address(views)
        self.units = profiles_by_address(views)
        self.rules = LineRules(self.units)
        # (what, the exchange or None, the address and instant of a restart)
        self._due: deque[tuple[str, Exchange | None, int, int]] = deque()

    # -- what the relay notes, in its order -------------------------------------------------
    def frame(self, ex: Exchange) -> None:
        """A frame came: it is read with its unit's checksum mode as of now."""
        ex.settle = self.settle
        self._due.append((FRAME, ex, 0, 0))

    def answered(self, ex: Exchange) -> None:
        """The unit answered ``ex`` (or never will): book it on every view."""
        self._due.append((ANSWERED, ex, 0, 0))

    def power_on(self, address: int, t: int) -> None:
        """The unit at ``address`` was power-cycled at ``t``."""
        self._due.append((POWER_ON, None, address, t))

    # -- reading and booking ----------------------------------------------------------------
    def settle(self) -> None:
        """Read and book everything noted so far."""
        due = self._due
        while due:
            kind, ex, address, t = due.popleft()
            if kind == FRAME:
                assert ex is not None
                view = self.view_at.get(_address(ex.frame.raw))
                ex.reading = self.rules.parse(ex.frame.raw, view is not None
                                                and view.checksums,
                                                lapsed=view is not None and view.lapsed)
                ex.vectors_before = self._vectors()
            elif kind == ANSWERED:
                assert ex is not None
                for view in self.views:
                    view.apply(ex, self.units)
            else:
                self.view_at[address].power_on(t)

    def vectors(self) -> int:
        """How many vectors the units have accepted so far."""
        self.settle()
        return self._vectors()

    def view(self, address: int | None) -> UnitView | None:
        """The view of the unit at ``address``, up to date (None: no unit there)."""
        self.settle()
        return self.view_at.get(address) if address is not None else None

    def _vectors(self) -> int:
        return sum(v.vectors for v in self.views)


def _address(raw: bytes) -> int | None:
    return raw[1] - 0x30 if len(raw) > 1 else None
