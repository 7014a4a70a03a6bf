"""The context flags a difference's labels read off its step alone: the frame's
address, case, parameters' forms, checksum as sent, and whether a packet was open."""

from __future__ import annotations

import re

from conformance.diff.grammar import load_grammar
from conformance.diff.labels import command_of
from conformance.diff.steps import Step
from conformance.protocol.catalogue import catalogue
from conformance.protocol.parse import parse, read_int
from gve_fixtures.profile import Profile

_LONG_DECIMAL = re.compile(r"\d{13,}")
#: W with a comma after its axis letter (the format line's form, not M114's example's)
_AXIS_COMMA = re.compile(r"W[A-Za-z],")


def step_flags(step: Step, profile: Profile, *, in_packet: bool, summing: bool) -> set[str]:
    """The flags of ``step`` on ``profile``: ``in_packet``: a packet was open before it;
    ``summing``: the target's checksum mode was on (a checksum sent bad or left out means
    something only then)."""
    g = load_grammar()["command"]
    name = command_of(step.body)
    entry = g.get(name, g.get(name + "0", {}))
    spindle = profile.spindle
    to_spindle = spindle is not None and step.address == spindle.address
    flags = {
        "other-address": step.address is not None and not to_spindle,
        "to-spindle": to_spindle,
        "stalled": step.stall is not None,
        "lower": _has_lower(step.body[:len(name)] if name else step.body),
        "lower-param": bool(name) and _has_lower(step.body[len(name):]),
        # the parameters after the wire name (SW6's is SW: `SW+6,00` has a plus)
        "plus": name != "%" and "+" in parse(step.body).params,
        # a space among the parameters (`SW 6,00`): what it means is spec 3's decision
        "space": bool(name) and " " in parse(step.body).params,
        "bad-checksum": step.checksum == "bad" and summing,
        "no-checksum": step.checksum == "none" and summing,
        "in-packet": in_packet,
        "extra-param": bool(name) and not entry.get("params") and name not in ("SW6",)
        and step.body.upper() != name,
        "long-decimal": bool(_LONG_DECIMAL.search(step.body)),
        "long-hex": long_hex(name, parse(step.body).fields),
        "axis-comma": name == "W" and axis_comma(step.body),
        "enables": name == "SW" and step.body[2:4] in ("0,", "1,"),
    }
    return {k for k, on in flags.items() if on}


def long_hex(name: str, fields: tuple[str, ...]) -> bool:
    """Whether a hex field of the frame has more than the two digits the manuals write
    (00..FF)."""
    command = catalogue().get(name)
    # a frame may carry more or fewer fields than the command takes
    return command is not None and any(
        f.kind == "hex" and len(v.strip()) > 2
        for f, v in zip(command.fields, fields, strict=False))


def axis_comma(body: str) -> bool:
    """Whether ``body`` is a W with a comma after its axis letter and every number within
    the catalogue's ranges: where the reference answers 5 it found no switch (a field out
    of range is the range's rule, whatever the form)."""
    if not _AXIS_COMMA.match(body):
        return False
    fields = parse(body).fields
    command = catalogue()["W"]
    if len(fields) != len(command.fields):
        return False
    for f, text in zip(command.fields, fields, strict=True):
        value = read_int(text, strict=True) if f.kind == "dec" else 0
        lo, hi = f.range if isinstance(f.range, tuple) else (value, value)
        if value is None or not lo <= value <= hi:
            return False
    return True


def _has_lower(text: str) -> bool:
    return any("a" <= ch <= "z" for ch in text)
