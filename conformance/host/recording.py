"""What the relay saw, both ways: every host frame with what the unit got, what it
answered and what the host was given (faults included), stray bytes, unsolicited
answers and the relay's own actions, each at its instant. The host rules and the
oracle judge this record after the run; the HTML report shows its wire log."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from conformance.host.frame_rules import ParsedFrame
from conformance.protocol.framer import Fragment, HostFrame
from gve_fixtures.transcript import ACTION, HOST, UNIT, Record, escape

#: a relay loop turn later than this (ns) is a stall of the relay itself, booked in
#: :attr:`Recording.stalls` and not held against hosts
STALL_NS = 20_000_000


@dataclass
class Exchange:
    """One host frame and what became of it.

    ``reading``: the frame as the judge reads it (None until the booking has read it,
    booking.py; :attr:`parsed` reads it when asked). ``to_unit``: the bytes the unit got
    for it (the frame itself, or what a fault made of it; None: nothing). ``answer``: the
    lines the unit answered (CR included; empty: none). ``delivered``: the bytes the host
    got (None: nothing, the answer was lost).
    """

    n: int
    frame: HostFrame
    reading: ParsedFrame | None = None
    to_unit: bytes | None = None
    answer: list[bytes] = field(default_factory=list)
    answered_at: int | None = None
    delivered: bytes | None = None
    delivered_at: int | None = None
    fault: str | None = None
    vectors_before: int = 0         # vectors the units had accepted before this frame
    settle: Callable[[], None] | None = field(default=None, repr=False, compare=False)

    @property
    def parsed(self) -> ParsedFrame:
        if self.reading is None and self.settle is not None:
            self.settle()
        assert self.reading is not None, "an exchange the booking never read"
        return self.reading

    @property
    def text(self) -> str:
        """The frame as the wire log writes it (CR left out, other bytes escaped)."""
        return show(self.frame.raw)

    @property
    def code(self) -> int | None:
        """The answer's error code (its INTA bit removed), None without an answer."""
        head = self.answer[-1][:1] if self.answer else b""
        return int(head, 16) & 7 if head and head in b"0123456789ABCDEF" else None

    @property
    def intact(self) -> bool:
        """Whether the host was given the unit's answer as the unit sent it."""
        return self.delivered is not None and self.delivered == b"".join(self.answer)


@dataclass
class Unsolicited:
    """Answer lines that belong to no complete frame (the watchdog's `2`, spec 3)."""

    lines: list[bytes]
    t: int
    delivered_at: int | None = None


@dataclass
class Recording:
    origin: int
    exchanges: list[Exchange] = field(default_factory=list)
    fragments: list[Fragment] = field(default_factory=list)
    unsolicited: list[Unsolicited] = field(default_factory=list)
    log: list[Record] = field(default_factory=list)
    faults: list[tuple[int, str]] = field(default_factory=list)
    stalls: list[tuple[int, int]] = field(default_factory=list)   # relay loop late
    settings: list[tuple[int, str]] = field(default_factory=list)  # the host's port setup

    def host_bytes(self, data: bytes, t: int) -> None:
        self.log.append(Record(HOST, data, t - self.origin))

    def unit_bytes(self, data: bytes, t: int, comment: str = "") -> None:
        self.log.append(Record(UNIT, data, t - self.origin, comment))

    def action(self, t: int, text: str, comment: str = "") -> None:
        self.log.append(Record(ACTION, text.encode("ascii", "replace"), t - self.origin,
                               comment))

    def fault(self, t: int, kind: str, detail: str) -> None:
        """An injected fault, marked on the wire log (spec-free text; bytes escaped)."""
        self.faults.append((t, f"{kind}: {detail}"))
        self.action(t, f"fault {kind}", detail)

    def wire_log(self) -> list[str]:
        return [record.line() for record in sorted(self.log, key=lambda r: r.t or 0)]


def show(data: bytes) -> str:
    """Bytes as the wire log writes them (``!0V1000\\r``)."""
    return escape(data)
