"""Safety on real units (issue 4 item 10): the motion envelope and destructive commands.

Real units are machines with spindles. The link asks this guard before sending a frame:
vectors that would take an axis beyond ``max_travel`` steps from where the session
began are refused (:class:`SafetyStop`), `J` and EEPROM writes need
``allow_destructive``, and every EEPROM byte is backed up before its first write so the
link can restore it at the end (and verify it by reading back).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field


class SafetyStop(Exception):
    """A frame the suite refused to send to a real unit."""


_VECTOR = re.compile(r"([LC])(-?\d+(?:,-?\d+)*)$")
_EEPROM_WRITE = re.compile(r"(EW|EFW|EUW)([0-9A-Fa-f]{1,2}),")
_WIDTH = {"EW": 1, "EFW": 4, "EUW": 4}


@dataclass
class Guard:
    enforce: bool                      # False on the emulator: nothing to protect
    max_travel: int
    allow_destructive: bool
    axes: int = 3
    position: list[int] = field(default_factory=lambda: [0, 0, 0, 0])
    eeprom_touched: set[int] = field(default_factory=set)

    def check(self, body: str) -> list[int]:
        """Raise SafetyStop if ``body`` may not be sent; returns EEPROM addresses that
        must be backed up first."""
        if not self.enforce:
            return []
        m = _VECTOR.match(body)
        if m:
            steps = [int(x) for x in m.group(2).split(",")]
            for i, s in enumerate(steps):
                if abs(self.position[i] + s) > self.max_travel:
                    raise SafetyStop(f"{body}: axis {i} would leave the envelope "
                                     f"±{self.max_travel} steps")
            return []
        if body.startswith("W"):
            raise SafetyStop("W moves to a switch: not run on real units by the suite")
        if body == "J" and not self.allow_destructive:
            raise SafetyStop("J restarts the unit: needs --allow-destructive")
        e = _EEPROM_WRITE.match(body)
        if e:
            if not self.allow_destructive:
                raise SafetyStop(f"{e.group(1)} writes EEPROM: needs --allow-destructive")
            start = int(e.group(2), 16)
            return [a for a in range(start, start + _WIDTH[e.group(1)])
                    if a not in self.eeprom_touched]
        return []

    def accepted(self, body: str) -> None:
        """Book a vector the unit accepted (answer code 0)."""
        m = _VECTOR.match(body)
        if m:
            for i, s in enumerate(int(x) for x in m.group(2).split(",")):
                self.position[i] += s
