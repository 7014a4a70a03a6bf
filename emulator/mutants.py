"""Deliberate bugs the emulator can plant, one at a time, to prove the suite's power.

A unit created with ``mutant=NAME`` (``gve://?model=...&mutant=NAME``,
``--mutant NAME``, ``--target emu:GVE84-100?mutant=NAME``) deviates from the spec in
exactly the way described here and nowhere else. The project's tests assert that the
conformance suite FAILs every mutant, naming the case that caught it, and PASSes the
clean emulator on every profile; the emulator's own tests show each mutant answering a
transcript of its rule differently from the clean emulator.

Each entry of mutants.toml names the spec sections it touches, what it gets wrong, and
the rule area it breaks (the spec section whose rules a case must check to catch it).
Most mutants are planted in the unit (`device.mutant.active(NAME)` where the behaviour
lives); those whose behaviour lives in the motion model are deviations of the stepper
core (:data:`CORE_DEVIATIONS`), planted alike in both cores.
"""

from __future__ import annotations

import contextlib
import tomllib
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import NamedTuple

from emulator.motion.interface import Deviation


class MutantSpec(NamedTuple):
    section: str          # the spec sections it touches
    description: str      # what it gets wrong
    area: str             # the rule area (spec section) a case must check to catch it


#: the registry's data, one table per mutant in the order listed
REGISTRY = Path(__file__).with_name("mutants.toml")


def _load(path: Path = REGISTRY) -> dict[str, MutantSpec]:
    with path.open("rb") as f:
        return {name: MutantSpec(**entry) for name, entry in tomllib.load(f).items()}


#: name -> (spec sections, what the mutant gets wrong, rule area)
MUTANTS: dict[str, MutantSpec] = _load()

#: mutants whose behaviour lives in the stepper core
CORE_DEVIATIONS: dict[str, Deviation] = {
    "zero-c-keeps-junction": Deviation.ZERO_LENGTH_JUNCTION,
    "dwell-between-continuous": Deviation.CONTINUOUS_DWELL,
    "halt-short-of-target": Deviation.HALT_SHORT,
    "junction-stops": Deviation.JUNCTION_STOPS,
    "junction-brake-ignored": Deviation.JUNCTION_UNBRAKED,
    "halt-without-ramp": Deviation.HALT_DEAD,
    "go-at-speed": Deviation.GO_AT_SPEED,
}


class UnknownMutant(ValueError):
    pass


#: while :func:`asked` records: the mutants the clean units' behaviour depended on
_asked: set[str] | None = None


@contextlib.contextmanager
def asked() -> Iterator[set[str]]:
    """Record, while the block runs, every mutant a clean unit's behaviour depended on:
    each name its units asked :meth:`Mutant.active`, and every core deviation once a
    unit built its stepper core. A mutant not among them cannot have changed what the
    units did in the block: up to the first question about it, a unit carrying it acts
    as the clean one does (the mutation sweep runs a case against it only then)."""
    global _asked
    outer, _asked = _asked, set()
    try:
        yield _asked
    finally:
        if outer is not None:
            outer |= _asked
        _asked = outer


@dataclass(frozen=True)
class Mutant:
    """The mutant a unit carries (or none). ``active(name)`` is the only question the
    emulator asks; on a unit with a mutant it raises for a name not in :data:`MUTANTS`
    so that a typo cannot silently plant nothing (the tests run every mutant)."""

    name: str | None = None

    def __post_init__(self) -> None:
        if self.name is not None and self.name not in MUTANTS:
            known = ", ".join(sorted(MUTANTS))
            raise UnknownMutant(f"unknown mutant {self.name!r} (known: {known})")

    def active(self, name: str) -> bool:
        if self.name is None:          # the clean unit asks on every frame: answer fast
            if _asked is not None:
                _asked.add(name)
            return False
        if name not in MUTANTS:
            raise UnknownMutant(f"the emulator asks for an unknown mutant {name!r}")
        return self.name == name

    @property
    def deviations(self) -> Deviation:
        """The stepper core's deviations this mutant plants."""
        if self.name is None and _asked is not None:
            _asked.update(CORE_DEVIATIONS)
        return CORE_DEVIATIONS.get(self.name or "", Deviation.NONE)


NONE = Mutant()
