"""The run's EEPROM bookkeeping on a real unit, owned by the guard: what the bytes were
as found, which ones a frame may have changed since they were last put back, and which
ones the run ever wrote. The guard refuses a write to a byte whose original it does not
hold; the session reads the originals, puts bytes back and verifies them."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field


@dataclass
class EepromLedger:
    originals: dict[int, int] = field(default_factory=dict)   # address -> byte as found
    written: set[int] = field(default_factory=set)   # may differ now: not put back yet
    touched: set[int] = field(default_factory=set)   # written by the run, put back since

    def copy(self) -> EepromLedger:
        """A copy whose writes change nothing here (the originals, never changed in
        place, are shared: a copy is made for every batch of frames told ahead)."""
        return EepromLedger(self.originals, set(self.written), set(self.touched))

    def found(self, originals: dict[int, int]) -> None:
        """The bytes as the run found them (read before its first EEPROM write)."""
        self.originals = dict(originals)

    def backed_up(self, address: int) -> bool:
        return address in self.originals

    def write(self, addresses: Iterable[int]) -> None:
        """A frame that may change ``addresses`` is going out."""
        self.written.update(addresses)

    def put_back(self, addresses: Iterable[int]) -> None:
        """``addresses`` read as found again (or a failure was reported for them)."""
        self.touched.update(addresses)
        self.written.clear()

    @property
    def ever_written(self) -> bool:
        """Whether the run wrote a byte (the end of the run then verifies every one)."""
        return bool(self.written or self.touched)
