"""How far from the host's clock a unit may have acted on a frame, as the line allows: the
timing band of every measured check and of ``diff``'s real-time comparison.

A real-time session measures the line's round trip before the first case (a few `?`
exchanges: min, median and max in ms, the byte time and the bytes' time of one exchange
at the baud rate; ``SessionReport.line``). The host knows when it began sending a frame
and when the answer had arrived; between them the line adds a latency each way (a USB
adapter's latency timer, the driver, the unit's own loop) that changes from frame to
frame. The band is that uncertainty on either side of the instant the host sees:

    one-way latency  = (median round trip − the exchange's bytes' time) / 2   (≥ 0)
    jitter           = max − min round trip
    band             = one-way latency + jitter + one byte's time

The median (the line's typical latency) is the session's. The jitter is that of the
round trips the case saw itself when it saw two or more (the line under load in the
middle of a run is not the line at its start, and one slow `?` among the session's five
must not blunt every case of the run), else the session's. In virtual time the line is
exact and the band is zero (:data:`EXACT`), never printed.

A frame answered only when what it does is done (H: when the motion has come to rest)
gives no round trip, and the line that carried it may have been slower than at any frame
before it (a host under load the instant it sent that one): how late the unit may have
acted on it is read from its own answer too (:func:`acted_within`; a rig input from the
rig's `ok` alike).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass

from gve_fixtures.protocol import SECOND


@dataclass(frozen=True)
class LineBand:
    """± seconds around the instant the host sees, in which the unit may have acted."""

    seconds: float = 0.0

    @property
    def ns(self) -> int:
        return math.ceil(self.seconds * SECOND)

    @property
    def exact(self) -> bool:
        return self.seconds == 0

    def steps(self, rate: float) -> int:
        """Steps an axis moving at up to ``rate`` steps/s covers over the band, either way."""
        return math.ceil(rate * self.seconds)

    def widen(self, lo: int, hi: int) -> tuple[int, int]:
        """The instants ``lo..hi`` (ns) widened by the band on both sides."""
        return lo - self.ns, hi + self.ns

    def __str__(self) -> str:
        return f"±{self.seconds * 1e3:.1f} ms line"


#: the embedded emulator's virtual clock: every instant known exactly
EXACT = LineBand()


def line_band(line: Mapping[str, float] | None, observed_ms: Iterable[float] = ()) -> LineBand:
    """The band of a line measured as ``line`` (``SessionReport.line``: ``min_ms``,
    ``median_ms``, ``max_ms``, ``byte_ms``, ``bytes_ms``; any of them may be missing),
    its jitter from the round trips ``observed_ms`` a case saw itself (ms) when there are
    two or more."""
    line = line or {}
    seen = sorted(observed_ms)
    trips = seen if len(seen) >= 2 else \
        [v for v in (line.get("min_ms"), line.get("max_ms")) if v is not None] + seen
    if not trips:
        return EXACT
    median = line.get("median_ms", seen[len(seen) // 2] if seen else trips[0])
    one_way = max(0.0, (median - line.get("bytes_ms", 0.0)) / 2)
    jitter = max(trips) - min(trips)
    return LineBand((one_way + jitter + line.get("byte_ms", 0.0)) / 1e3)


def acted_within(sent_at: int, answered_at: int, takes_ns: int, latency_ns: int) -> int:
    """How long after ``sent_at`` (ns) a unit may have acted on a frame: up to the slowest
    round trip an immediate answer took (``latency_ns``), and up to when its own answer
    had come (``answered_at``) less what the frame takes before it answers
    (``takes_ns``: an H's braking, by the reference's answer or the model's; 0 for an
    answer at once, a rig's `ok`), whatever the line added to this one frame alone."""
    return max(0, latency_ns, answered_at - takes_ns - sent_at)
