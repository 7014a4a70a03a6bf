"""The session: what the unit keeps about the conversation rather than the machine
(spec 6, 7, 8): the checksum mode, the index, the last answered frame for `>`, and the
members of an open packet. A reset (power-on, `J`) starts a new session; on the GVE114
addresses 0 and 7 share one."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Member:
    """A frame received inside an open packet: its command (None: unknown), its parsed
    value, and the code it would fail the packet with (0: valid)."""

    name: str | None
    value: object
    code: int


class Session:
    def __init__(self, checksums: bool = False) -> None:
        self.reset(checksums)

    def reset(self, checksums: bool) -> None:
        self.checksums = checksums
        self.index = 0
        self.history: tuple[bytes, bytes] | None = None   # last answered frame, its answer
        self.packet: list[Member] | None = None          # None: no packet open

    def count(self) -> None:
        """One more frame counted in the index (modulo 256, spec 8)."""
        self.index = (self.index + 1) & 0xFF
