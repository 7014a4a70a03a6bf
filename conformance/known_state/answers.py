"""The unit's answers as the known state, the as-found read and the restorations read
them: ST6 at rest or not, "not yet", the counters of `PF`, an answer as a report shows
it."""

from __future__ import annotations

from conformance.link.framing import Response, readable
from conformance.protocol.wire import is_hex_byte
from gve_fixtures.protocol import ErrorCode, St6

#: ST6 bits that keep a unit from being at rest for a case: moving, braking, or
#: interrupted with vectors waiting for `G` (spec 10.3: INTA/RUN 0/0 is idle [M])
NOT_AT_REST = St6.RUN | St6.STOP | St6.INTA
#: the codes a frame refused only while something runs may get: 7 ("za chodu vektoru
#: nelze") and 1 (`L` while anything is queued or running): "not yet", never a refusal
NOT_YET = (ErrorCode.BUSY, ErrorCode.QUEUE_FULL)



def shown(r: Response | None) -> str:
    """An answer as a report says it: its bytes escaped but its last CR, or that none
    came."""
    return "nothing" if r is None else readable(r.raw.removesuffix(b"\r"))


def taken(r: Response | None) -> bool:
    return r is not None and r.ok


def refused_range(r: Response | None) -> bool:
    return r is not None and r.code is not None and r.code & 7 == ErrorCode.RANGE


def not_yet(r: Response | None) -> bool:
    """Whether ``r`` refuses its frame only while something runs (7, 1: not yet)."""
    return r is not None and r.code is not None and r.code & 7 in NOT_YET


def shown_counters(read: dict[int, int]) -> str:
    """Counters as PF shows them: ``394,0,0`` (``?`` for an axis not read)."""
    return ",".join(str(v) for v in read.values()) if read else "nothing readable"


def bits(st6: Response | None) -> St6:
    """ST6 as an `SR6` answer gives it (every bit set when it gives none: not at rest)."""
    return St6(st6.hex()) if hex_ok(st6) else St6(0xFF)


def rests(st6: Response | None) -> bool:
    """Whether an `SR6` answer shows the unit at rest (RUN, STOP and INTA clear)."""
    return not bits(st6) & NOT_AT_REST


def left(st6: Response | None) -> str:
    """What an `SR6` answer shows left (" (RUN, INTA)"), or nothing."""
    if not hex_ok(st6):
        return ""
    names = [b.name for b in (St6.RUN, St6.STOP, St6.INTA) if st6.hex() & b]
    return f" ({', '.join(n or '' for n in names)})" if names else ""


def hex_ok(r: Response | None) -> bool:
    return r is not None and r.ok and len(r.values) >= 1 and is_hex_byte(r.values[0])
