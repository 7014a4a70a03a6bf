"""``emu:PROFILE[?mutant=NAME&reading=A,B]``: the embedded emulator in virtual time, a
fresh unit per link. The only place the suite imports the emulator, and only to open its
``gve://`` URL (here, and for ``serial:gve://``) and to read its registries of mutants,
readings and URL settings."""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from urllib.parse import parse_qs, urlsplit

import serial

from conformance.link.virtual import line_of
from conformance.targets.info import EMULATOR, TargetInfo
from conformance.targets.target import Target, TargetError, known_settings
from gve_fixtures.profile import load_profile

#: the settings an ``emu:`` target takes
SETTINGS = ("mutant", "reading")


def register_url_scheme() -> None:
    """Make pyserial open the emulator's ``gve://`` URLs (importing it registers them)."""
    import emulator  # noqa: F401


def url_settings() -> tuple[str, ...]:
    """The settings the emulator's ``gve://`` URL takes, from the emulator itself."""
    from emulator.link.url import PARAMETERS
    return PARAMETERS


def mutants() -> dict[str, tuple[str, str]]:
    """The emulator's deliberate bugs: name -> (the rule area a case must check to catch
    it, what it gets wrong), from its registry."""
    from emulator.mutants import MUTANTS
    # an entry is (sections, description[, area]); the area defaults to the first section
    return {name: (spec[2] if len(spec) > 2 else spec[0].split(",")[0].strip(), spec[1])
            for name, spec in MUTANTS.items()}


@contextlib.contextmanager
def mutants_reached() -> Iterator[set[str]]:
    """The mutants whose code the clean embedded units of the block reached (the
    emulator's record of them): a case whose clean run reached none of a mutant's code
    runs against that mutant exactly as against the clean unit."""
    from emulator.mutants import asked
    with asked() as names:
        yield names


def version_text(prog: str) -> str:
    """``prog --version``: the version, the emulator's C stepper core's state, the Python."""
    from emulator.about import version_text as text
    return text(prog)


def emulator_readings() -> dict[str, tuple[tuple[str, ...], str]]:
    """The readings the emulator can take: name -> (the rules read otherwise, what it
    does), from its registry."""
    from emulator.readings import READINGS
    return {name: (spec.rules, spec.description) for name, spec in READINGS.items()}


class EmuTarget(Target):
    def preflight(self) -> None:
        if self.mutant is not None and self.mutant not in mutants():
            raise TargetError(f"unknown mutant {self.mutant!r} "
                              f"(known: {', '.join(sorted(mutants()))})")

    def connect(self, address: int | None):
        register_url_scheme()
        address = self.address if address is None else address
        query = f"model={self.profile.name}&address={address}"
        if self.mutant:
            query += f"&mutant={self.mutant}"
        if self.readings:
            query += f"&reading={self.readings}"
        port = serial.serial_for_url(f"gve://?{query}", timeout=0.25)
        line = line_of(port)
        return port, line.baud, True, line


def parse(kind: str, rest: str, *, spec: str, profile: str | None, allow_destructive: bool,
          max_travel: int, mutant: str | None, strict: bool = False) -> Target:
    parts = urlsplit("x://h/" + rest)
    name = parts.path.lstrip("/") or "GVE84-100"
    q = parse_qs(parts.query, keep_blank_values=True)
    known_settings(spec, q, SETTINGS)
    mutant = q.get("mutant", [mutant])[-1]
    readings = ",".join(q.get("reading", []))
    p = load_profile(name)
    if profile is not None and load_profile(profile).name != p.name:
        raise TargetError(f"--profile {profile} contradicts the target {spec} "
                          f"(the emulator behaves as {p.name})")
    if readings:
        unknown = sorted(set(readings.split(",")) - set(emulator_readings()))
        if unknown:
            raise TargetError(f"unknown reading(s) {', '.join(unknown)} "
                              f"(known: {', '.join(sorted(emulator_readings()))})")
    # the reference implements every decision: graded strictly, its mutants too; an
    # emulator taking other readings is graded as any other unit, by the tags
    info = TargetInfo(EMULATOR, spec, True, True, True, max_travel,
                      strict=not readings or strict)
    return EmuTarget(info, p, p.address, p.default_baud, spec, mutant, readings)
