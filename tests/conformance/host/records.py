"""Building recordings by hand, as the relay would have seen them: frames at instants
(milliseconds), the unit's answers, what the host was given and when."""

from __future__ import annotations

from conformance.host.checks import LineFacts, judge
from conformance.host.frame_rules import parse_frame
from conformance.host.recording import Exchange, Recording
from conformance.host.unitview import line_views
from conformance.protocol.framer import HostFrame
from gve_fixtures.profile import load_profile

MS = 1_000_000
PROFILE = load_profile("GVE84-100")
UNITS = {0: PROFILE}


class Wire:
    """A recording built one exchange at a time."""

    def __init__(self, units: dict | None = None) -> None:
        self.units = units or UNITS
        self.rec = Recording(0)

    def frame(self, raw: bytes, at_ms: float, *, answer: bytes | None = b"0\r",
              given_ms: float | None = None, lost: bool = False, fault: str | None = None,
              gap_ms: float = 0.0, checksums: bool = False, given: bytes | None = None
              ) -> Exchange:
        """``raw`` sent from ``at_ms`` (``gap_ms`` between its bytes); the unit answers
        ``answer`` at once; the host is given it (or ``given``) at ``given_ms`` (default:
        1 ms after the CR), or never when ``lost``."""
        t0 = round(at_ms * MS)
        times = [t0 + round(i * gap_ms * MS) for i in range(len(raw))]
        end = times[-1] + round(gap_ms * MS)
        ex = Exchange(len(self.rec.exchanges), HostFrame(raw, times, end),
                      parse_frame(raw, self.units, checksums), to_unit=raw + b"\r",
                      fault=fault)
        if answer is not None:
            ex.answer, ex.answered_at = [answer], end
            if not lost:
                ex.delivered = answer if given is None else given
                ex.delivered_at = round(given_ms * MS) if given_ms is not None else end + MS
        self.rec.exchanges.append(ex)
        return ex

    def judge(self, exit_code: int | None = 0):
        views = line_views([(p, a) for a, p in self.units.items()])
        return judge(self.rec, LineFacts(views, self.units, 115200, 0, exit_code=exit_code))


def broken(j) -> dict[str, list[str]]:
    """Rule -> the frames that broke it."""
    out: dict[str, list[str]] = {}
    for f in j.findings:
        if f.tag is None:
            out.setdefault(f.rule, []).append(f.frame)
    return out
