"""``emu:PROFILE[?mutant=NAME]``: the embedded emulator in virtual time, a fresh unit per
link. The only place the suite imports the emulator: to open its ``gve://`` URL, and to
list the deliberate bugs it can plant (:func:`mutants`)."""

from __future__ import annotations

from urllib.parse import parse_qs, urlsplit

from conformance.case import TargetInfo
from conformance.targets.base import Target
from gve_fixtures.profile import load_profile


def parse(kind: str, rest: str, *, spec: str, profile: str | None, allow_destructive: bool,
          max_travel: int, mutant: str | None) -> Target:
    parts = urlsplit("x://h/" + rest)
    name = parts.path.lstrip("/") or "GVE84-100"
    q = parse_qs(parts.query)
    mutant = q.get("mutant", [mutant])[-1]
    p = load_profile(profile or name)
    info = TargetInfo("emu", spec, True, True, True, max_travel)
    return Target(info, p, p.address, p.default_baud, spec, mutant)


def mutants() -> dict[str, tuple[str, str]]:
    """Every mutant the emulator can plant: name -> (the rule area a case must check to
    catch it, what it gets wrong), from the emulator's registry."""
    from emulator.mutants import MUTANTS
    # an entry is (sections, description[, area]); the area defaults to the first section
    return {name: (spec[2] if len(spec) > 2 else spec[0].split(",")[0].strip(), spec[1])
            for name, spec in MUTANTS.items()}
