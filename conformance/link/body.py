"""A frame's body as the guard and its bookkeeping read it: leniently (a unit that is
not conforming may take `l` for `L` or `+5` for 5), so that no reading of it goes
unjudged; and what an answer says of a frame's outcome."""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

from conformance.link.envelope import UNKNOWN, ZERO, Outcome, Span, point
from conformance.link.framing import Response
from conformance.protocol.parse import parse


@dataclass(frozen=True)
class Body:
    """A frame's body read leniently: its class and its parameters."""

    name: str
    params: str

    @classmethod
    @lru_cache(maxsize=4096)     # every frame is parsed several times; a Body is immutable
    def parse(cls, body: str) -> Body:
        """The frame's class (``SW6`` for a write of ST6, "" for no command of spec 10)
        and its parameters, read leniently."""
        parsed = parse(body)
        return cls(parsed.key, parsed.params)

    def fields(self, count: int) -> tuple[Span, ...]:
        """The first ``count`` comma-separated integers (missing ones 0, unreadable ones
        unbounded)."""
        return _fields(self.params, count)


@lru_cache(maxsize=4096)     # a vector's fields are read when it is judged and booked
def _fields(params: str, count: int) -> tuple[Span, ...]:
    parts = params.split(",") if params else []
    return tuple(number(parts[i]) if i < len(parts) else ZERO for i in range(count))


def number(text: str, base: int = 10) -> Span:
    """An integer read leniently: empty is 0, unreadable is unbounded."""
    text = text.strip().lstrip("+")
    if text == "":
        return ZERO
    try:
        return point(int(text, base))
    except ValueError:
        return UNKNOWN


def outcome_of(r: Response | None) -> Outcome:
    """What an answer says a frame did: taken, refused, or unclear (none, or no code)."""
    if r is None or r.code is None:
        return Outcome.UNCLEAR
    return Outcome.ACCEPTED if r.ok else Outcome.REFUSED
