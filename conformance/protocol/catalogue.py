"""The command catalogue (``commands.toml``): what the suite knows of each command of
spec 10, read once. Every reader of the suite asks it instead of keeping its own list.

A command is known by its wire name (``O``, ``SW``); a write of ST6 is classed ``SW6``
as well (its own entry, derived from ``SW`` with the properties of ``[command.SW.st6]``).
"""

from __future__ import annotations

import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field, fields, replace
from functools import cache
from pathlib import Path
from types import MappingProxyType

from gve_fixtures.profile import KNOWN_COMMANDS

CATALOGUE_FILE = Path(__file__).with_name("commands.toml")
#: the class of a frame that writes status word ST6 (spec 10.3)
ST6_WRITE = "SW6"
PACKET_ROLES = ("opens", "member", "breaker", "closes")
RESUMED = ("queue", "save")


@dataclass(frozen=True)
class Field:
    """One parameter: its syntax (``kind``) and its valid values."""

    kind: str                                   # dec, hex, float, word
    range: str | tuple[int, int] | None = None
    choices: tuple[str, ...] = ()
    syntax: str = ""                            # the rule its format breaks, if not the kind's


@dataclass(frozen=True)
class Command:
    """One entry of the catalogue (the keys of ``commands.toml``, documented there)."""

    name: str
    fields: tuple[Field, ...] = ()
    repeat: str | None = None
    glued: bool = False
    rules: tuple[str, ...] = ()
    profile_name: str = ""
    count_rule: str = "5.code.syntax"
    answer: bool = True
    lines: int = 1
    deferred: bool = False
    restart: bool = False
    indexed: bool = True
    remembered: bool = True
    motion: bool = False
    destructive: bool = False
    eeprom: int = 0
    reads: int = 0
    packet: str | None = None
    checksums: bool = False
    vector: bool = False
    modal: bool = False
    setting: bool = False
    marks: bool = False
    course: bool = False
    retimes: bool = False
    stops: bool = False
    asks: bool = False
    reaction: bool = False
    position: bool = False
    optional: bool = False
    exchanges: bool = False
    paces: bool = False
    own_speed: bool = False
    empties: bool = False
    still: bool = False
    summing: bool = False
    query: bool = False
    resumes: str | None = None
    examples: tuple[str, ...] = field(default=(), compare=False)

    @property
    def known_as(self) -> str:
        """The name a profile's command set uses."""
        return self.profile_name or self.name

    @property
    def ends_packet(self) -> bool:
        """Whether it ends an open packet: `*E` closes it, a breaker discards it (spec 7)."""
        return self.packet in ("breaker", "closes")

    @property
    def repeatable(self) -> bool:
        """Whether running it twice leaves what running it once does (M84 12.5.12:
        "Většina příkazů se dá zopakovat (A,V,PF atd..)"): a setting or a read, not a
        vector, a marker, a motion, a stop, a restart or a packet's end."""
        return not (self.vector or self.motion or self.marks or self.stops or self.restart
                    or self.empties or self.packet in ("opens", "closes"))

    @property
    def switch(self) -> bool:
        """Whether it is a modal switch: modal, with no value (`VK` / `VN`)."""
        return self.modal and not self.fields


_FLAGS = {f.name for f in fields(Command)} - {"name", "fields", "rules", "examples",
                                              "profile_name", "count_rule"}
_KEYS = {"fields", "rules", "profile", "count", "examples", "st6", *_FLAGS}


@cache
def catalogue(path: Path = CATALOGUE_FILE) -> dict[str, Command]:
    """Every command by its wire name, in spec 10's order, and ``SW6`` after ``SW``."""
    raw = tomllib.loads(path.read_text(encoding="utf-8"))
    table: dict[str, Command] = {}
    for name, entry in raw["command"].items():
        unknown = set(entry) - _KEYS
        if unknown:
            raise ValueError(f"{path.name}: command {name!r}: unknown key(s) {sorted(unknown)}")
        if entry.get("packet") not in (None, *PACKET_ROLES):
            raise ValueError(f"{path.name}: command {name!r}: packet {entry['packet']!r}")
        if entry.get("resumes") not in (None, *RESUMED):
            raise ValueError(f"{path.name}: command {name!r}: resumes {entry['resumes']!r}")
        command = Command(
            name, tuple(Field(f["kind"], _range(f.get("range")), tuple(f.get("choices", ())),
                              f.get("syntax", "")) for f in entry.get("fields", ())),
            rules=tuple(entry.get("rules", ())), profile_name=entry.get("profile", ""),
            count_rule=entry.get("count", "5.code.syntax"),
            examples=tuple(entry.get("examples", ())),
            **{k: entry[k] for k in _FLAGS if k in entry})
        table[name] = command
        if "st6" in entry:
            st6 = entry["st6"]
            table[ST6_WRITE] = replace(command, name=ST6_WRITE,
                                       examples=tuple(st6.get("examples", ())),
                                       **{k: st6[k] for k in _FLAGS if k in st6})
    known = {c.known_as for n, c in table.items() if n != ST6_WRITE}
    if known != KNOWN_COMMANDS:
        raise ValueError(f"{path.name}: the commands differ from the profiles' known "
                         f"commands: {sorted(known ^ KNOWN_COMMANDS)}")
    return table


def _range(value: object) -> str | tuple[int, int] | None:
    if isinstance(value, list):
        return (int(value[0]), int(value[1]))
    return value if isinstance(value, str) else None


def commands() -> Mapping[str, Command]:
    """The commands of spec 10 by wire name (without the ``SW6`` class); built once
    (read per frame by the suite), read-only."""
    return _commands()


@cache
def _commands() -> Mapping[str, Command]:
    return MappingProxyType({n: c for n, c in catalogue().items() if n != ST6_WRITE})


@cache
def classes(**wanted: object) -> frozenset[str]:
    """The names (``SW6`` among them) whose entries have every property ``wanted``:
    ``classes(motion=True)``, ``classes(packet="breaker")``."""
    return frozenset(n for n, c in catalogue().items()
                     if all(getattr(c, k) == v for k, v in wanted.items()))


@cache
def names_longest_first() -> tuple[str, ...]:
    """The wire names, longest first (so that `PF` is not read as `P`)."""
    return tuple(sorted(commands(), key=len, reverse=True))


def eeprom_width(name: str) -> int:
    """Bytes of EEPROM a write of ``name`` changes (0: not an EEPROM write)."""
    command = catalogue().get(name)
    return command.eeprom if command is not None else 0


def eeprom_read_width(name: str) -> int:
    """Bytes of EEPROM a read of ``name`` answers (0: not an EEPROM read)."""
    command = catalogue().get(name)
    return command.reads if command is not None else 0
