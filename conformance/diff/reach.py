"""What a search reached, counted beside its verdict: the commands the grammar can send
on the profile (each answered by the reference at least once), the table values (both
ends of every range the grammar draws a field from, every word of a field of words,
every value the profile's tables list: the MPG enable byte's, the spindle's ends, each
input grounded), and the states of a unit its answers show (grammar.toml `[reach]`).
A value counts when the reference took it (answered 0); a state when the reference's
answer to a frame shows it."""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from conformance.diff.grammar import Options, command_names, load_grammar, table_values
from conformance.diff.sides import RoundTrip
from conformance.diff.steps import FILL, FRAME, INPUT, Step
from conformance.protocol.catalogue import commands
from conformance.protocol.parse import parse
from gve_fixtures.profile import Profile
from gve_fixtures.protocol import ErrorCode


@dataclass(frozen=True)
class State:
    name: str
    frame: re.Pattern[str]
    answer: re.Pattern[str]
    requires: tuple[str, ...] = ()       # commands the run must send to reach it
    keep: str = ""                       # the profile's queue after K it needs

    def reachable(self, profile: Profile, names: list[str]) -> bool:
        return (all(c in names for c in self.requires)
                and (not self.keep or profile.keep == self.keep))


@dataclass
class Figure:
    """One kind of thing reached: how many of how many, and which were not."""

    reached: int
    total: int
    missing: list[str] = field(default_factory=list)

    @property
    def text(self) -> str:
        return f"{self.reached}/{self.total}"


class Reach:
    """The commands, table values and states a search reached on one profile and run."""

    def __init__(self, profile: Profile, options: Options) -> None:
        g = load_grammar()
        self.profile = profile
        names = command_names(profile, options)
        self.commands = dict.fromkeys(names, False)
        self._fields: dict[str, list[tuple[int, str, list[str]]]] = {}
        self.values: dict[str, bool] = {}
        for name in names:
            entry = g["command"][name]
            for i, kind in enumerate(entry.get("params", []) if entry.get("tables", True)
                                     else []):
                ends = table_values(profile, kind)
                if ends:
                    self._fields.setdefault(name, []).append((i, kind, ends))
                    for v in ends:
                        self.values[_value_id(name, i, v, entry)] = False
        self._tables = self._profile_tables(options)
        for key in self._tables.values():
            for v in key:
                self.values[v] = False
        self._state_list = [s for s in _states(g) if s.reachable(profile, names)]
        self.states = {s.name: False for s in self._state_list}
        #: the matrix's cells that apply to the model (matrix.py), each True once it ran
        self.cells: dict[str, bool] = {}

    def matrix(self, every: list, ran: list) -> None:
        """The matrix's cells (matrix.Cell): those the model has, and those that ran; a
        cell left out for this run (no rig, no --allow-destructive) is one not reached."""
        done = {c.name for c in ran}
        self.cells = {c.name + (f" ({c.left_out})" if c.left_out else ""): c.name in done
                      for c in every if not c.meaningless}

    def _profile_tables(self, options: Options) -> dict[str, list[str]]:
        """The values the profile's own tables list (not a command's range)."""
        p, out = self.profile, {}
        if p.mpg is not None and options.destructive and "EW" in p.commands:
            listed = sorted(p.mpg.enabling_values)
            beside = sorted({(v + d) & 0xFF for v in listed for d in (-1, 1)} - set(listed))
            out["mpg"] = [f"EW{p.mpg.enable_address:02X}={v:02X}" for v in listed + beside]
        if p.spindle is not None:
            r = p.spindle.range
            out["spindle"] = [f"!{p.spindle.address}V={v}" for v in (r.lo, r.lo + 1, r.hi)]
        if options.rig:
            out["inputs"] = [f"I{port} bit {b} grounded" for port in p.input_ports
                             for b in range(8)]
        return out

    # -- what a step reached -----------------------------------------------------------------
    def took(self, step: Step, reference: RoundTrip | None) -> None:
        if step.kind == INPUT:
            for b in range(8):
                key = f"I{step.port} bit {b} grounded"
                if not step.value >> b & 1 and key in self.values:
                    self.values[key] = True
            return
        if step.kind not in (FRAME, FILL) or reference is None:
            return
        parsed = parse(step.body)
        command = commands().get(parsed.name or "")
        name = command.known_as if command is not None else ""
        answer = reference.answer.decode("latin-1")
        spindle = self.profile.spindle
        if spindle is not None and step.address == spindle.address:
            if parsed.name == "V" and reference.code is not None and reference.code & 7 == 0:
                self._mark(f"!{spindle.address}V={parsed.params}")
            return
        if step.address is not None:
            return
        if name in self.commands and (reference.response is not None or not command.answer):
            self.commands[name] = True
        for s in self._state_list:
            if not self.states[s.name] and s.frame.search(step.body) \
                    and s.answer.search(answer):
                self.states[s.name] = True
        # a value counts where the reference took it: not refused for its form or range
        # (a reference run's 5 is where its switch was not: W took its fields)
        refused = (ErrorCode.UNKNOWN, ErrorCode.SYNTAX) + (() if command is not None
                                                          and command.deferred
                                                          else (ErrorCode.RANGE,))
        if reference.code is None or reference.code & 7 in refused:
            return
        entry = load_grammar()["command"].get(name, {})
        for i, kind, ends in self._fields.get(name, ()):
            if i < len(parsed.fields):
                value = _read(kind, parsed.fields[i])
                if value in ends:
                    self._mark(_value_id(name, i, value, entry))
        if name == "EW" and len(parsed.fields) == 2:
            self._mark(f"EW{_read('hex', parsed.fields[0])}={_read('hex', parsed.fields[1])}")

    def _mark(self, key: str) -> None:
        if key in self.values:
            self.values[key] = True

    # -- the figures -----------------------------------------------------------------------
    def figures(self) -> dict[str, Figure]:
        out = {}
        for kind, table in (("commands", self.commands), ("table values", self.values),
                            ("states", self.states), ("matrix cells", self.cells)):
            if kind == "matrix cells" and not table:
                continue
            out[kind] = Figure(sum(table.values()), len(table),
                               [k for k, ok in table.items() if not ok])
        return out

    @property
    def share(self) -> float:
        figs = self.figures().values()
        total = sum(f.total for f in figs)
        return 100.0 * sum(f.reached for f in figs) / total if total else 100.0

    def line(self) -> str:
        """``reached: commands 46/48, table values 95/120, states 14/16 (92 %)``."""
        figs = self.figures()
        return ("reached: " + ", ".join(f"{k} {f.text}" for k, f in figs.items())
                + f" ({self.share:.0f} %)")

    def not_reached(self) -> list[str]:
        return [f"{k}: {', '.join(f.missing)}" for k, f in self.figures().items() if f.missing]


def _read(kind: str, text: str) -> str:
    """A field as the table names its values (hex: two upper-case digits; decimal: as a
    number, leading zeros off)."""
    try:
        if kind.startswith("hex"):
            return "%02X" % int(text, 16)
        if kind.startswith(("range", "dec")):
            return str(int(text))
    except ValueError:
        return text
    return text.upper()


def _value_id(name: str, i: int, value: str, entry: dict) -> str:
    """``V=10``, ``SW#2=FF`` (the field's place where the command has several)."""
    place = f"#{i + 1}" if len(entry.get("params", [])) > 1 else ""
    return f"{name}{place}={value}"


def _states(g: dict) -> list[State]:
    return [State(s["name"], re.compile(s["frame"]), re.compile(s["answer"]),
                  tuple(s.get("requires", ())), s.get("keep", ""))
            for s in g.get("reach", {}).get("state", [])]
