"""Who is on the line: ask a unit `?` and `Q` — two questions that move
nothing — and pick its profile for ``--profile auto``; ``ports --probe`` asks `?` alone.

The family comes from the firmware string: a profile whose `?` answer is exactly that
string, else the family its leading name gives (``IP84 v3 …`` → GVE84). The variant
comes from the string only where it decides (one profile answers it); the spec gives
every GVE84 one string and every GVE114 another (spec 1), so there the variant is taken
from ``--variant``, or asked on a terminal, or the run is refused with the choices.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass

import serial

from conformance.link.exclusive import LeftAlone, open_serial, settings_kept
from conformance.link.framing import frame, parse_response
from conformance.targets.target import Target
from conformance.verdicts.quoting import escaped, shown
from gve_fixtures.profile import Profile, available_profiles, load_profile
from gve_fixtures.protocol import ErrorCode

#: how long one question waits for its answer (no unit answers `?` slower)
ANSWER_SECONDS = 0.3


@dataclass(frozen=True)
class Identity:
    version: str             # the answer to `?`
    processor_id: str        # the answer to `Q`
    baud: int                # the rate it answered at


def profiles() -> list[Profile]:
    return [load_profile(name) for name in available_profiles()]


def bauds(given: int | None = None) -> list[int]:
    """The rates to try: ``given``, else the profiles' defaults, then the other rates
    they support (the most common first)."""
    if given is not None:
        return [given]
    every = profiles()
    first = sorted({p.default_baud for p in every}, reverse=True)
    rest = sorted({b for p in every for b in p.bauds} - set(first), reverse=True)
    return first + rest


def _ask(port: serial.SerialBase, address: int, body: str) -> str | None:
    """The value of the answer to ``body`` (None when nothing sensible came). A unit left
    in checksum mode answers 4 to a frame without one: ask again with it."""
    for summed in (False, True):
        port.reset_input_buffer()
        port.write(frame(body, address, summed))
        raw = port.read_until(b"\r")
        if not raw.endswith(b"\r"):
            return None
        r = parse_response(raw, summed=summed)
        if r.ok and r.values:
            return ",".join(r.values)
        if r.code != ErrorCode.SYNTAX:
            return None
    return None


def ask(url: str, address: int, rates: list[int],
        open_port: Callable[..., serial.SerialBase] = open_serial, *,
        processor_id: bool = True) -> Identity | None:
    """The unit's identity at the first rate where it answers `?`, or None; its `Q`
    asked too unless ``processor_id`` is False (then "")."""
    for baud in rates:
        port = open_port(url, baudrate=baud, timeout=ANSWER_SECONDS)
        try:
            version = _ask(port, address, "?")
            if version is not None:
                found = _ask(port, address, "Q") if processor_id else None
                return Identity(version, found or "", baud)
        finally:
            port.close()
    return None


def family_of(version: str) -> str | None:
    """The family a firmware string names (``Ip54v3`` → GVE54), if a profile has it."""
    m = re.match(r"[A-Za-z]+\s*(\d+)", version)
    family = f"GVE{m.group(1)}" if m else None
    return family if family in {p.family for p in profiles()} else None


def candidates(version: str) -> list[Profile]:
    """The profiles a unit answering ``version`` to `?` may be."""
    exact = [p for p in profiles() if p.version == version]
    family = family_of(version)
    found = exact or [p for p in profiles() if p.family == family]
    return sorted(found, key=lambda p: p.max_rate)


def variant_of(name: str) -> str:
    """``GVE84-100`` → ``100`` (a one-variant family: its name)."""
    return name.partition("-")[2] or name


def choose(identity: Identity, variant: str | None = None,
           ask_variant: Callable[[list[Profile]], str | None] | None = None
           ) -> tuple[Profile, str]:
    """The profile for ``identity`` and how it was chosen; ValueError when it cannot be."""
    found = candidates(identity.version)
    if not found:
        raise ValueError(f"the unit answered ? with {shown(identity.version)}, which no profile "
                         "knows: give --profile (or add a profile: fixtures/README.md)")
    if len(found) == 1:
        return found[0], f"auto: ? answered {shown(identity.version)}"
    family = found[0].family
    choices = ", ".join(variant_of(p.name) for p in found)
    why = f"auto: ? answered {shown(identity.version)}, the same for {choices}"
    if variant is None and ask_variant is not None:
        variant, why = ask_variant(found), why + "; variant given by the operator"
    elif variant is not None:
        why += "; --variant"
    if variant is None:
        raise ValueError(f"the unit is a {family} ({escaped(identity.version)}), but its "
                         f"answer does not say which variant: give --variant ({choices})")
    for p in found:
        if variant in (p.name, variant_of(p.name)):
            return p, why
    raise ValueError(f"--variant {variant}: a {family} is one of {choices}")


#: what a probe says of a port where nothing answered `?`
SILENT = "no GVE unit answered"


def probe(url: str, address: int = 0) -> str:
    """What `gve-conformance ports --probe` says of the port at ``url``: the unit that
    answers `?` (asked nothing else), no answer, or why the port was skipped untouched
    (another program holds it; not a terminal). Its settings are put back afterwards."""
    try:
        with settings_kept(url):
            identity = ask(url, address, bauds(), processor_id=False)
    except LeftAlone as err:
        return f"skipped: {err}"
    except (serial.SerialException, OSError, ValueError):
        return SILENT
    if identity is None:
        return SILENT
    family = family_of(identity.version) or "unknown family"
    return f"{family}: ? {shown(identity.version)} at {identity.baud} baud, address {address}"


def of_target(target: Target) -> Identity | None:
    """What the target answers to `?` and `Q`, for the report (nothing that moves)."""
    if not target.info.real:
        link = target.open_link()
        version, processor_id = link.send("?"), link.send("Q")
        if version is None or processor_id is None:
            return None
        return Identity(",".join(version.values), ",".join(processor_id.values), target.baud)
    return ask(target.url, target.address, [target.baud])
