"""Targets: where the suite's links go, one small module per scheme (as pyserial's URL
handlers are): ``emu:PROFILE`` (emu.py, the embedded emulator in virtual time),
``serial:PATH?baud=&address=`` and ``tcp:HOST:PORT`` (port.py, a unit or a clone's
simulator in real time), ``exec:COMMAND`` (process.py, a simulator the suite starts,
with its control channel as the test rig). :func:`parse_target` picks the module by the scheme; the
run-wide session (session.py) opens links and keeps the unit safe."""

from __future__ import annotations

from conformance.targets import emu, port, process
from conformance.targets.info import EMULATOR
from conformance.targets.session import Session, SessionError, SessionReport
from conformance.targets.target import DEFAULT_MAX_TRAVEL, Target, TargetError
from gve_fixtures.profile import Profile

__all__ = ["DEFAULT_MAX_TRAVEL", "SCHEMES", "Session", "SessionError", "SessionReport",
           "Target", "TargetError", "parse_target"]

#: scheme -> the module that parses it (``parse(kind, rest, **options) -> Target``)
SCHEMES = {EMULATOR: emu, "serial": port, "tcp": port, "exec": process}


def parse_target(spec: str, *, profile: str | None = None, allow_destructive: bool = False,
                 max_travel: int = DEFAULT_MAX_TRAVEL, mutant: str | None = None,
                 strict: bool = False) -> Target:
    """A target from its command-line text (``emu:GVE84-100``, ``serial:/dev/ttyUSB0``...).
    ``strict``: grade a target that is not the reference emulator by the project's
    decisions too (the reference always is). Raises TargetError (or LookupError for an
    unknown profile) with one line to show."""
    kind, _, rest = spec.partition(":")
    module = SCHEMES.get(kind)
    if module is None:
        raise TargetError(f"unknown target {spec!r}: use emu:PROFILE, "
                          "serial:PATH?baud=&address=, tcp:HOST:PORT, or exec:COMMAND")
    target = module.parse(kind, rest, spec=spec, profile=profile,
                          allow_destructive=allow_destructive, max_travel=max_travel,
                          mutant=mutant, strict=strict)
    within_vector_range(max_travel, target.profile)
    return target


def within_vector_range(max_travel: int, profile: Profile) -> None:
    """The one bound of ``--max-travel``, on every target and in every subcommand (the
    embedded emulator's too: the same command line must mean the same on every target):
    1 to the profile's vector range (TargetError otherwise)."""
    if not 0 < max_travel <= profile.vector_range:
        raise TargetError(f"--max-travel {max_travel}: the envelope is 1 to "
                          f"{profile.vector_range} full steps on the {profile.name} "
                          "(its vector range)")
