"""Deliberate host bugs, one switch each (`python -m gve_host ... --bug NAME`): realistic
mistakes of host programs, planted where the correct behaviour is written
(``if self.bugs.on("blind-resend")``), so that the certification can show it fails each
of them with a named rule or scenario."""

from __future__ import annotations

BUGS: dict[str, str] = {
    "no-wait": "sends the next command without waiting for the answer to the last",
    "blind-resend": "resends a command whose answer was lost, without asking `@`",
    "queue-full-ignored": "takes answer 1 (queue full) for success",
    "wrong-checksum": "sums its checksums one too high",
    "lower-case": "writes its commands in lower case",
    "lf-terminator": "ends its frames with LF instead of CR",
    "slow-bytes": "pauses 150 ms between the bytes of a frame (longer than the watchdog)",
    "wrong-address": "addresses the unit one above the one it was given",
    "packet-miscount": "gives `*E` one member more than it sent",
    "ignore-inta": "does not look at INTA in answers",
    "overlong-frames": "pads numbers with leading zeros past 96 bytes a frame",
    "non-integer": "writes settings and vectors as decimals (`V10000.0`)",
    "early-position": "reads the position of a checkpoint before the motion has ended",
    "ignore-answer-checksums": "trusts answers whose checksum does not add up",
    "wait-forever": "waits for a lost answer forever",
    "two-stop-bits": "sets its port to two stop bits (a PLC's default)",
}


class Bugs:
    def __init__(self, names: list[str] | None = None) -> None:
        unknown = [n for n in names or [] if n not in BUGS]
        if unknown:
            raise ValueError(f"unknown bug(s): {', '.join(unknown)} (see --list-bugs)")
        self.names = frozenset(names or [])

    def on(self, name: str) -> bool:
        assert name in BUGS, name
        return name in self.names
