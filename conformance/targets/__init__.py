"""Targets: where the suite's links go, one small module per scheme (as pyserial's URL
handlers are): ``emu:PROFILE`` (emu.py, the embedded emulator in virtual time),
``serial:PATH?baud=&address=`` and ``tcp:HOST:PORT`` (port.py, a unit or a clone's
simulator in real time). :func:`parse_target` picks the module by the scheme."""

from __future__ import annotations

from conformance.targets import emu, port
from conformance.targets.base import DEFAULT_MAX_TRAVEL, Target, known_state

__all__ = ["DEFAULT_MAX_TRAVEL", "SCHEMES", "Target", "known_state", "parse_target"]

#: scheme -> the module that parses it (``parse(kind, rest, **options) -> Target``)
SCHEMES = {"emu": emu, "serial": port, "tcp": port}


def parse_target(spec: str, *, profile: str | None = None, allow_destructive: bool = False,
                 max_travel: int = DEFAULT_MAX_TRAVEL, mutant: str | None = None) -> Target:
    """A target from its command-line text (``emu:GVE84-100``, ``serial:/dev/ttyUSB0``...)."""
    kind, _, rest = spec.partition(":")
    module = SCHEMES.get(kind)
    if module is None:
        raise ValueError(f"unknown target {spec!r}: use "
                         "emu:PROFILE, serial:PATH?baud=&address=, or tcp:HOST:PORT")
    return module.parse(kind, rest, spec=spec, profile=profile,
                        allow_destructive=allow_destructive, max_travel=max_travel,
                        mutant=mutant)
