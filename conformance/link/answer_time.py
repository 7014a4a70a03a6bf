"""How long a frame's answer may take beyond its bytes: at once for most commands, at
the end of their motion for `H` and `W`, which answer when it ends (spec 10). A stop is
bounded by the envelope the guard keeps: braking at the smallest acceleration over the
longest distance the envelope allows."""

from __future__ import annotations

import math

from conformance.link.envelope import Envelope
from conformance.protocol.parse import parse
from gve_fixtures.profile import Profile

#: the longest an answer is waited for (a `W` whose run would take longer: the unit
#: refuses such a travel or rate, or the run is not one a test should wait out)
LONGEST_ANSWER_S = 600.0


def _fields(params: str, count: int) -> list[int | None]:
    """The first ``count`` comma-separated integers, read leniently (missing: 0,
    unreadable: None)."""
    parts = params.split(",") if params else []
    out: list[int | None] = []
    for i in range(count):
        text = parts[i].strip().lstrip("+") if i < len(parts) else ""
        try:
            out.append(int(text) if text else 0)
        except ValueError:
            out.append(None)
    return out


class AnswerTime:
    """The answer times of one unit's frames, from its profile and the envelope its
    axes are kept in (read as it stands)."""

    def __init__(self, profile: Profile, envelope: Envelope) -> None:
        self.profile = profile
        self.envelope = envelope

    def stop_seconds(self) -> float:
        """The longest a stop can take (`H` answers when it ends): braking at the
        smallest acceleration over the longest distance the envelope allows (both
        directions), or from the fastest rate where there is no envelope."""
        a_min = self.profile.range("A").lo * 1000.0 * self.envelope.factor.lo
        if math.isinf(self.envelope.limit):
            return self.profile.max_rate / a_min
        return math.sqrt(2 * 2 * self.envelope.limit / a_min)

    def answer_seconds(self, body: str) -> float | None:
        """How long `H` and `W` may take before they answer (None: at once)."""
        parsed = parse(body)
        if parsed.key == "H":
            return 2 * self.stop_seconds()
        if parsed.key == "W":
            n2, n3, n4, n5 = _fields(parsed.params[1:].lstrip(","), 4)
            if None not in (n2, n3, n4, n5) and n3 > 0 and n5 > 0:
                run = abs(n2) / n3 + abs(n4) / n5 + 4 * self.stop_seconds()
                return min(run, LONGEST_ANSWER_S)
            return LONGEST_ANSWER_S
        return None
