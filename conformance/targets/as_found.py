"""The unit as the session found it before the first case, and the reads that take it:
what the restorations put back and verify."""

from __future__ import annotations

from dataclasses import dataclass, field

from conformance.link.framing import Response, frame
from conformance.link.link import Link

#: EEPROM bytes read back in one go (one exchange with a co-simulator that takes frames
#: told ahead, docs/cosim.md: `batch`; a frame at a time on any other unit)
EEPROM_READS = 64
#: `?` exchanges that measure the line's round trip at the start of a session
ROUND_TRIPS = 5


@dataclass
class AsFound:
    """What the session read of the unit before the run changed anything (its EEPROM is
    the guard's ledger's)."""

    identity: dict[str, str] = field(default_factory=dict)
    status: dict[int, int] = field(default_factory=dict)       # ST0..ST5
    checksums: bool | None = None                               # the checksum mode
    counters: dict[int, int] = field(default_factory=dict)     # position counters (PF)


def read_eeprom(link: Link, addresses: list[int]) -> dict[int, Response | None]:
    """`ER` of each address in turn, EEPROM_READS frames told ahead at a time."""
    read: dict[int, Response | None] = {}
    for start in range(0, len(addresses), EEPROM_READS):
        chunk = addresses[start:start + EEPROM_READS]
        read.update(zip(chunk, link.send_each(["ER%02X" % a for a in chunk]), strict=True))
    return read



def round_trip(link: Link) -> dict[str, float]:
    """The round trip of a harmless `?` in ms (min, median, max), one byte's time at the
    link's baud rate and the time of one exchange's bytes (frame and answer): what the
    line adds to every exchange (conformance/link/line_band.py)."""
    answers = [r for r in (link.send("?") for _ in range(ROUND_TRIPS)) if r is not None]
    trips = sorted((r.received_at - r.sent_at) / 1e6 for r in answers)
    if not trips:
        return {}
    sent = len(frame("?", link.address, link.checksums))
    return {"min_ms": trips[0], "median_ms": trips[len(trips) // 2], "max_ms": trips[-1],
            "byte_ms": link.byte_seconds(1) * 1e3,
            "bytes_ms": link.byte_seconds(sent + len(answers[0].raw)) * 1e3}
