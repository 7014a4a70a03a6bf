"""What a feature configured in EEPROM needs before a unit can do it, as the manuals say
(``preconditions.toml``): every parameter they name for the feature, the values each
allows, and how it is read and written. A case that depends on a feature establishes it
before relying on it (conformance/cases/_kit.py ``configured``)."""

from __future__ import annotations

import math
import re
import tomllib
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cache
from pathlib import Path

from gve_fixtures.profile import Profile

PRECONDITIONS_FILE = Path(__file__).with_name("preconditions.toml")
#: a number as a unit writes one (decimal, optional fraction and exponent)
_NUMBER = re.compile(r"-?\d+(\.\d*)?([eE][-+]?\d+)?")


@dataclass(frozen=True)
class Kind:
    """How a parameter of one kind is read and written (spec 10.6)."""

    read: str
    write: str
    hex: bool = False


@dataclass(frozen=True)
class Parameter:
    name: str
    address: int
    kind: Kind
    allowed: tuple[tuple[float, float], ...]
    value: float
    families: tuple[str, ...] = ()         # () = every family of its feature

    def read(self) -> str:
        """The frame that reads it."""
        return f"{self.kind.read}{self.address:02X}"

    def write(self) -> str:
        """The frame that writes the value the manual allows."""
        return f"{self.kind.write}{self.address:02X},{self.text(self.value)}"

    def text(self, value: float) -> str:
        """``value`` as the unit writes it: two hex digits, or a decimal."""
        return "%02X" % int(value) if self.kind.hex else f"{value:g}"

    def holds(self, values: Sequence[str]) -> bool:
        """Whether an answer's values show an allowed value (one that cannot be read as a
        number is not: it is written over)."""
        text = values[0] if values else ""
        try:
            if self.kind.hex:
                found = float(int(text, 16)) if re.fullmatch(r"[0-9A-Fa-f]{2}", text) else None
            else:
                found = float(text) if _NUMBER.fullmatch(text) else None
        except ValueError:
            found = None
        return found is not None and math.isfinite(found) and any(
            lo <= found <= hi for lo, hi in self.allowed)

    @property
    def shown(self) -> str:
        ranges = ", ".join(self.text(lo) + (f"..{self.text(hi)}" if hi != lo else "")
                           for lo, hi in self.allowed)
        return f"{self.name} (EEPROM {self.address:02X}: {ranges})"


@dataclass(frozen=True)
class Feature:
    name: str
    families: tuple[str, ...]
    source: str
    params: tuple[Parameter, ...]

    def params_for(self, profile: Profile) -> tuple[Parameter, ...]:
        """What ``profile``'s unit needs set, in the order it is written (none where the
        feature does not concern its family)."""
        if profile.family not in self.families:
            return ()
        return tuple(p for p in self.params if not p.families or profile.family in p.families)


@cache
def features(path: Path = PRECONDITIONS_FILE) -> dict[str, Feature]:
    raw = tomllib.loads(path.read_text(encoding="utf-8"))
    kinds = {name: Kind(k["read"], k["write"], k.get("hex", False))
             for name, k in raw["kind"].items()}
    out = {}
    for name, f in raw["feature"].items():
        params = tuple(Parameter(p["name"], int(p["address"], 16), kinds[p["kind"]],
                                 tuple((float(lo), float(hi)) for lo, hi in p["allowed"]),
                                 p["value"], tuple(p.get("families", ())))
                       for p in f["param"])
        bad = [p.name for p in params if not p.holds([p.text(p.value)])]
        if bad:
            raise ValueError(f"{path.name}: feature {name}: the value written is not allowed "
                             f"for {', '.join(bad)}")
        out[name] = Feature(name, tuple(f["families"]), f["source"], params)
    return out


def feature(name: str) -> Feature:
    return features()[name]
