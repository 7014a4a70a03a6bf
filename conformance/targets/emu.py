"""``emu:PROFILE[?mutant=NAME]``: the embedded emulator in virtual time, a fresh unit per
link. The only place the suite imports the emulator, and only to open its ``gve://`` URL."""

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
