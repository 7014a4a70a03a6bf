"""What a session found, did and could not do: for the console and the reports."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field


@dataclass
class SessionReport:
    """What the session found, did and could not do: for the console and the reports."""

    target: str
    profile: str
    axes: list[str]
    real: bool
    identity: dict[str, str] = field(default_factory=dict)
    max_travel: int | None = None                   # full steps either side; None: emulator
    excursion: list[list[float]] | None = None      # per axis [min, max] in full steps
    found: dict[str, str] = field(default_factory=dict)
    restored: list[str] = field(default_factory=list)
    reset: list[str] = field(default_factory=list)   # could not be read: set to reset state
    problems: list[str] = field(default_factory=list)
    interrupted: bool = False
    not_responding: str = ""
    violations: list[str] = field(default_factory=list)   # answers outside the cases
    #: the line's round trip measured at the start (`?` exchanges): ms min, median, max,
    #: and the byte time at the baud rate
    line: dict[str, float] = field(default_factory=dict)
    #: where the session's time went: seconds per head of conformance/link/account.py
    #: and the wall time
    time: dict[str, float] = field(default_factory=dict)
    wire_log: list[str] = field(default_factory=list)

    def to_dict(self) -> dict:
        return asdict(self)
