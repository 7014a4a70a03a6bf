"""A host's command frame judged against spec 3 and 10: address, command, parameters,
checksum and length, each problem naming the rule it breaks (fixtures/rules.toml).

Written from the spec. The parameters are the suite's command catalogue
(conformance/protocol/commands.toml); the ranges come from the addressed unit's profile.
"""

from __future__ import annotations

import math
import re
import struct
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cache

from conformance.protocol.bounded import decimal, hexadecimal
from conformance.protocol.catalogue import Command, Field, classes, commands
from conformance.protocol.parse import parse
from conformance.protocol.wire import HEX_BYTE, byte_sum
from conformance.verdicts.quoting import escaped
from gve_fixtures.profile import Profile
from gve_fixtures.protocol import MAX_FRAME
from gve_fixtures.rules import load_rules

_DEC = re.compile(r"-?[0-9]+\Z")
_HEX = re.compile(r"[0-9A-Fa-f]+\Z")
_FLOAT = re.compile(r"-?[0-9]+(\.[0-9]+)?([eE][-+]?[0-9]+)?\Z")
#: a read sent without its sum in checksum mode (spec 6 [D])
UNSUMMED = "6.checksum.unsummed-query"
_SUM = re.compile(rb",(%b)\Z" % HEX_BYTE.encode(), re.IGNORECASE)
_PRINTABLE = re.compile(rb"[\x20-\x7e]*")
#: what a host might put between parameters instead of a comma (spec 3 [M] "commas")
_SEPARATORS = re.compile(r"[ ;:\t]")
_SYNTAX_RULE = {"dec": "3.params.decimal", "hex": "3.params.hex-fields",
                "float": "3.params.float-syntax", "word": "5.code.syntax"}


def command_table() -> dict[str, Command]:
    """The commands of spec 10 by wire name (the suite's catalogue)."""
    return commands()


@dataclass(frozen=True)
class Problem:
    """One rule a frame breaks, and how."""

    rule: str
    what: str


@dataclass
class ParsedFrame:
    """A host's frame as the judge reads it (``raw`` from `!` to the byte before CR)."""

    raw: bytes
    address: int | None = None
    body: str = ""                  # without the checksum
    command: str | None = None      # the command's wire name, read strictly (spec 3)
    key: str = ""                   # the frame's class, read leniently (`SW6`: writes ST6)
    params: list[str] = field(default_factory=list)
    checksum: str | None = None
    problems: list[Problem] = field(default_factory=list)
    judged: set[str] = field(default_factory=set)      # every rule this frame was held to

    @property
    def text(self) -> str:
        return self.raw.decode("latin-1")

    def problem(self, rule: str, what: str) -> None:
        self.problems.append(Problem(rule, what))

    def check(self, ok: bool, rule: str, what: str | Callable[[], str]) -> bool:
        """Hold the frame to ``rule``; record ``what`` (text, or a function that writes
        it, called only then) when it breaks it."""
        self.judged.add(rule)
        if not ok:
            self.problem(rule, what if isinstance(what, str) else what())
        return ok


def parse_frame(raw: bytes, units: dict[int, Profile], checksums: bool) -> ParsedFrame:
    """Judge one frame; ``units`` maps the addresses on the line to their profiles,
    ``checksums`` is the checksum mode the addressed unit is in (spec 6)."""
    return _parse(raw, units, checksums)


def command_of(raw: bytes, units: dict[int, Profile]) -> str | None:
    """The command :func:`parse_frame` finds in a frame, without judging the rest (what
    the relay needs while the frame is on the line). A checksum is not cut off first: its
    `,XX` never lengthens a name, as no name has a comma."""
    digit = raw[1:2]
    if not (digit.isdigit() and int(digit) <= 7 and int(digit) in units):
        return None
    return parse(raw[2:].decode("latin-1"), strict=True).name


class LineRules:
    """:func:`parse_frame` for one line, remembering its answers: hosts repeat frames
    (polls, retries). A parsed frame is shared between equal frames: do not change it."""

    def __init__(self, units: dict[int, Profile], size: int = 4096) -> None:
        self.units, self.size = units, size
        self._seen: dict[tuple[bytes, bool, bool], ParsedFrame] = {}

    def parse(self, raw: bytes, checksums: bool, *, lapsed: bool = False) -> ParsedFrame:
        found = self._seen.get((raw, checksums, lapsed))
        if found is None:
            found = self._seen[raw, checksums, lapsed] = _parse(raw, self.units, checksums,
                                                               lapsed)
            if len(self._seen) > self.size:
                self._seen.pop(next(iter(self._seen)))
        return found


def _parse(raw: bytes, units: dict[int, Profile], checksums: bool,
           lapsed: bool = False) -> ParsedFrame:
    f = ParsedFrame(raw)
    f.check(len(raw) <= MAX_FRAME, "3.frame.max-length",
            lambda: f"{len(raw)} bytes, more than {MAX_FRAME}")
    f.check(_PRINTABLE.fullmatch(raw) is not None, "3.frame.grammar",
            "a byte that is not printable ASCII inside the frame")
    digit = raw[1:2]
    if not f.check(digit.isdigit() and int(digit) <= 7, "3.frame.grammar",
                   "no address 0..7 after `!`"):
        return f
    f.address = int(digit)
    profile = units.get(f.address)
    if not f.check(profile is not None, "2.link.addressed-only",
                   lambda: f"address {f.address}: no unit on the line has it"):
        return f
    assert profile is not None
    body = raw[2:]
    if checksums:
        m = _SUM.search(body)
        if f.check(m is not None, "6.checksum.sum",
                   "checksum mode is on and the frame has no checksum"):
            assert m is not None
            f.checksum = m.group(1).decode()
            expected = byte_sum(raw[: len(raw) - 2])
            f.check(int(f.checksum, 16) == expected, "6.checksum.sum",
                    lambda: f"checksum {f.checksum}, the bytes sum to {expected:02X}")
            body = body[: m.start()]
    elif lapsed:
        # a frame summed as checksum mode wants, after a restart turned the mode off:
        # that is the finding, not what the unit makes of the sum as a parameter
        m = _SUM.search(body)
        if m is not None and int(m.group(1), 16) == byte_sum(raw[: len(raw) - 2]):
            f.check(False, "6.checksum.off-after-reset",
                    "a frame with its checksum after a restart turned checksum mode off")
            body = body[: m.start()]
    f.body = body.decode("latin-1")
    _command(f, profile)
    if checksums and f.checksum is None and f.command is not None \
            and commands()[f.command].query:
        # a read sent without its sum is refused and not run ("jednotka příkaz
        # neprovede a nahlásí chybu", M114 13.3.2): a host's probe of the mode, its own
        # choice; nothing it needed was left undone
        f.problems = [Problem(UNSUMMED, p.what) if p.rule == "6.checksum.sum" else p
                      for p in f.problems]
        f.judged.add(UNSUMMED)
    return f


def _command(f: ParsedFrame, profile: Profile) -> None:
    table = command_table()
    name = parse(f.body, strict=True).name
    classed = parse(f.body)
    upper = classed.name
    lower = name is None and upper is not None
    # the frame's class is every reader's (lower case too); what the unit does with it
    # (``command``) is read as spec 3 writes it, as the conforming units behind the relay read it
    f.key = classed.key
    f.check(not lower, "3.frame.upper-case",
            lambda: f"command letters `{escaped(f.body[: len(upper or '')])}` are not upper case")
    if not f.check(name is not None or lower, "1.profile.command-set",
                   lambda: f"`{escaped(f.body[:3])}…` is no command of spec 10") or name is None:
        return
    command = table[name]
    f.command = name
    spindle = profile.spindle is not None and f.address == profile.spindle.address
    allowed = profile.spindle.commands if spindle else profile.commands
    family_lacks = name in classes(checksums=True) and profile.family == "GVE54"
    where = f"address {f.address} of the {profile.name}" if spindle else profile.name
    if not f.check(command.known_as in allowed,
                   "1.profile.gve54-no-checksums" if family_lacks else "1.profile.command-set",
                   lambda: f"`{name}`: the {where} has no such command"):
        return
    _params(f, command, f.body[len(name):], profile, spindle)


def _params(f: ParsedFrame, command: Command, text: str, profile: Profile,
            spindle: bool) -> None:
    if not command.fields:
        f.check(not text, "3.params.none-expected", f"`{command.name}` takes no parameters")
        return
    parts: list[str] = []
    if command.glued:
        parts, text = [text[:1]], text[1:]
        if text.startswith(","):
            text = text[1:]
    if text or not command.glued:
        parts += text.split(",")
    f.params = parts
    counts = _counts(command, profile)
    rule = command.count_rule
    if _SEPARATORS.search(text):
        rule = "3.params.commas"
    elif command.repeat == "axes" and len(parts) > len(profile.axes):
        rule = "1.profile.axes"
    if not f.check(len(parts) in counts, rule,
                   lambda: f"`{command.name}` takes {' or '.join(map(str, counts))} "
                           f"parameter(s), the frame has {len(parts)}"):
        return
    fields = [*command.fields, *[command.fields[-1]] * (len(parts) - len(command.fields))]
    for spec, value in zip(fields, parts, strict=True):
        rule, problem = _value(spec, value, command, profile, spindle)
        f.check(problem is None, rule, problem or "")


def _counts(command: Command, profile: Profile) -> tuple[int, ...]:
    if command.repeat == "axes":
        return tuple(range(3, len(profile.axes) + 1))
    return (len(command.fields),)


def _value(spec: Field, text: str, command: Command, profile: Profile,
           spindle: bool) -> tuple[str, str | None]:
    """The rule a parameter is held to, and what is wrong with it (None: nothing)."""
    syntax = spec.syntax or _SYNTAX_RULE[spec.kind]
    if spec.kind == "word":
        ok = text in spec.choices
        return syntax, None if ok else (f"`{command.name}`: `{escaped(text)}` is not one of "
                                        f"{' '.join(spec.choices)}")
    if spec.kind == "float":
        if not _FLOAT.match(text):
            return syntax, f"`{escaped(text)}` is not a decimal number"
        return syntax, None if _float32(float(text)) else f"`{escaped(text)}` is no finite float32"
    pattern, base = (_DEC, 10) if spec.kind == "dec" else (_HEX, 16)
    if not pattern.match(text):
        what = "decimal integer" if base == 10 else "hexadecimal number"
        return syntax, f"`{command.name}`: `{escaped(text)}` is not a {what}"
    value = decimal(text, signed=True) if base == 10 else hexadecimal(text)
    if value is None:           # more digits than any field of the protocol has
        return syntax, f"`{command.name}`: `{text[:40]}...` has {len(text)} digits"
    lo, hi = _bounds(spec, profile, spindle and command.name == "V")
    rules = ("12.spindle.speed",) if spindle and command.name == "V" else command.rules
    rule = _applicable(rules, profile.name, profile.family)
    return rule, None if lo <= value <= hi else (f"`{command.name}`: {value} outside "
                                                 f"{lo}..{hi}")


def _bounds(spec: Field, profile: Profile, spindle: bool) -> tuple[int, int]:
    if spindle and profile.spindle is not None:
        return profile.spindle.range.lo, profile.spindle.range.hi
    if isinstance(spec.range, tuple):
        return spec.range
    if spec.range == "vector":
        return -profile.vector_range, profile.vector_range
    r = profile.range(str(spec.range))
    return r.lo, r.hi


@cache
def _applicable(rules: tuple[str, ...], name: str, family: str) -> str:
    known = load_rules()
    for rule in rules:
        if rule in known and known[rule].applies_to(name, family):
            return rule
    return "5.code.range"


def _float32(value: float) -> bool:
    if not math.isfinite(value):
        return False
    try:
        struct.pack("<f", value)
    except OverflowError:
        return False
    return True
