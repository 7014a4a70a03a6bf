"""The steps written in the grammar's data rather than drawn: an idiom's lines (the
grammar's scenarios and tables, the matrix's set-ups), the probes (``probes.toml``) run
whole before the search draws, and the tables swept whole after them. One profile's and
run's: a written step the profile or the run cannot send is left out whole."""

from __future__ import annotations

import re
import tomllib
from dataclasses import replace
from functools import cache
from pathlib import Path

from conformance.diff.labels import command_of
from conformance.diff.steps import FILL, FRAME, INPUT, RIG, STATE, WAIT, Step
from conformance.protocol.catalogue import Command, commands
from gve_fixtures.profile import Profile

PROBES_FILE = Path(__file__).with_name("probes.toml")
#: an idiom's vector along the first axis only
_ONE_COMPONENT = re.compile(r"[LC]-?\d+")
#: how an idiom's frame is sent, written before its body, and what that changes of the step
_SENT = {
    "bad": lambda profile: {"checksum": "bad"},
    "stalled": lambda profile: {"stall": (2, (profile.watchdog_ms + 50) / 1000)},
    "other": lambda profile: {"address": (profile.address + 1) % 8, "answer": False},
    "spindle": lambda profile: {"address": profile.spindle.address},
}
_PREFIX = re.compile(r"^(%s):" % "|".join(_SENT))
#: the rig's acts besides an input, written as its control channel's words (docs/rig.md)
_SWITCH = re.compile(r"switch ([XYZA]) (-?\d+|none)")


@cache
def load_probes(path: Path = PROBES_FILE) -> tuple[dict, ...]:
    return tuple(tomllib.loads(path.read_text(encoding="utf-8"))["probe"])


class Written:
    """The written steps of one profile and run: ``rig``: both sides have one (the run
    allows its hands), ``allowed``: the names an idiom's frame may have, ``g``: the
    grammar's data (grammar.toml: how each command is answered)."""

    def __init__(self, profile: Profile, rig: bool, allowed: set[str], g: dict) -> None:
        self.profile = profile
        self.rig = rig
        self.allowed = allowed
        self.g = g

    def can(self, idiom: list[str]) -> bool:
        """Whether every step of an idiom can be sent on this profile and run."""
        allowed = self.allowed
        for f in idiom:
            if f.startswith("input "):
                if not (self.rig and int(f.split()[1]) in self.profile.input_ports):
                    return False
            elif f.startswith("fill "):
                if command_of(f.split()[2]) not in allowed:
                    return False
            elif f.startswith("wait "):
                continue
            elif f == "state" or f == "power-on" or _SWITCH.fullmatch(f):
                if not self.rig:
                    return False
            elif (command_of(_PREFIX.sub("", f)) not in allowed
                  or (f.startswith("spindle:") and self.profile.spindle is None)):
                return False
        return True

    def idiom(self, lines: list[str] | tuple[str, ...]) -> list[Step]:
        """The steps an idiom (or a probe) is written as: `wait S`, `input P XX`, `state`,
        `fill N BODY`, `bad:BODY` (a wrong checksum in checksum mode), `stalled:BODY` (a
        pause longer than the watchdog after its second byte), `other:BODY` (to another
        address), `spindle:BODY` (to the GVE114's spindle address), else a frame; `J` is
        followed by its restart's wait."""
        out = []
        for f in lines:
            word, _, rest = f.partition(" ")
            if word == "wait":
                out.append(Step(WAIT, seconds=float(rest)))
            elif f == "state":
                out.append(Step(STATE))
            elif f == "power-on":
                out += [Step(RIG, f), self.restart_wait()]
            elif _SWITCH.fullmatch(f):
                out.append(Step(RIG, f))
            elif word == "input":
                port, value = rest.split()
                out.append(Step(INPUT, port=int(port), value=int(value, 16)))
            elif word == "fill":
                times, body = rest.split()
                out.append(Step(FILL, self._padded(body), times=int(times)))
            elif m := _PREFIX.match(f):
                step = self.fixed(self._padded(f[m.end():]))
                out.append(replace(step, **_SENT[m.group(1)](self.profile)))
            else:
                out.append(self.fixed(self._padded(f)))
                if self.g["command"].get(command_of(f), {}).get("then_wait") == "restart":
                    out.append(self.restart_wait())
        return _silent_in_packets(out)

    def fixed(self, body: str, checksum: str = "auto") -> Step:
        """A frame written in the grammar (an event, an idiom's step), answered as its
        command is: `>`'s two lines (the frame it repeats, then the answer), none after
        `*S`."""
        entry = self.g["command"].get(command_of(body), {})
        return Step(FRAME, body, checksum, answer=entry.get("answer", True),
                    lines=entry.get("lines", 1))

    def _padded(self, body: str) -> str:
        """An idiom's one-component vector (`C100`) with the profile's other axes 0."""
        if _ONE_COMPONENT.fullmatch(body):
            return body + ",0" * (len(self.profile.axes) - 1)
        return body

    def probes(self) -> list[tuple[dict, list[Step]]]:
        """The probes of ``probes.toml`` this profile and run can send, with their steps."""
        return [(p, self.idiom(p["steps"])) for p in load_probes()
                if self.profile.family in p.get("families", [self.profile.family])
                and self.can(p["steps"])]

    def sweep(self, tables: list[tuple[str, ...]]) -> list[list[Step]]:
        """The ``tables`` run whole once, after the probes: every table value of a command in
        one sequence (its frames one after the other), then each idiom of the profile's
        tables, so that the default budget reaches every value whatever the draw."""
        single = [t[0] for t in tables if len(t) == 1]
        by_command: dict[str, list[str]] = {}
        for body in single:
            by_command.setdefault(command_of(body), []).append(body)
        return ([self.idiom(bodies) for bodies in by_command.values()]
                + [self.idiom(t) for t in tables if len(t) > 1])

    def restart_wait(self) -> Step:
        return Step(WAIT, seconds=self.profile.restart_ms / 1000 + 0.05)


def tabled(profile: Profile, idiom: list[str]) -> list[tuple[str, ...]]:
    """An idiom of `[tables]` once per value of the profile's table its placeholder
    names (none where the profile has no such table)."""
    tables: dict[str, list[str]] = {}
    if profile.mpg is not None:
        listed = sorted(profile.mpg.enabling_values)
        beside = sorted({(v + d) & 0xFF for v in listed for d in (-1, 1)} - set(listed))
        tables["mpg"] = ["%02X" % v for v in listed + beside]
        tables["mpg_address"] = ["%02X" % profile.mpg.enable_address]
    if profile.spindle is not None:
        r = profile.spindle.range
        tables["spindle"] = [str(v) for v in (r.lo + 1, r.hi)]
    if profile.microstep is not None:
        tables["microstep"] = [*profile.microstep.factors, *profile.microstep.currents]
    axes = len(profile.axes)
    tables["axis_alone"] = [",".join("100" if j == i else "0" for j in range(axes))
                            for i in range(axes)]
    tables["port"] = [str(port) for port in profile.input_ports]
    # the interrupt inputs behind each status word with several of them: enabled, grounded
    # at once, the cause word read (ST0/2/4 are I1's, ST1/3/5 I2's)
    tables["sources"] = [{"enable": str(word), "mask": "%02X" % mask, "port": str(word + 1),
                          "cause": str(word + 4), "one": "%02X" % (mask & -mask)}
                         for word, mask in enumerate((profile.low_mask, profile.high_mask))
                         if bin(mask).count("1") > 1 and word + 1 in profile.input_ports]
    wanted = sorted({m.group(1) for m in _PLACEHOLDER.finditer(" ".join(idiom))})
    if any(not tables.get(name) for name in wanted):
        return []
    out: list[tuple[str, ...]] = [tuple(idiom)]
    for name in wanted:
        out = [tuple(_filled(line, name, value) for line in lines)
               for lines in out for value in tables[name]]
    return out


#: `{name}`, or `{name.key}` for one of a table's values that are several together
_PLACEHOLDER = re.compile(r"\{([a-z_]+)(?:\.([a-z_]+))?\}")


def _filled(line: str, name: str, value: str | dict[str, str]) -> str:
    if isinstance(value, dict):
        for key, part in value.items():
            line = line.replace("{%s.%s}" % (name, key), part)
        return line
    return line.replace("{%s}" % name, value)


@cache
def _commands() -> dict[str, Command]:
    """The catalogue's commands, read once (every idiom's frames look theirs up)."""
    return commands()


def _silent_in_packets(steps: list[Step]) -> list[Step]:
    """The frames of an open packet are answered by nothing until one ends it (`*E`, a
    breaker: spec 7), as a drawn packet's members are sent: a frame that waited for an
    answer would time out and make the line keep quiet after it."""
    out, open_packet = [], False
    for step in steps:
        if step.kind == FRAME:
            command = _commands().get(command_of(step.body))
            ends = command is not None and command.ends_packet
            if open_packet and not ends:
                step = replace(step, answer=False)
            open_packet = ((command is not None and command.packet == "opens")
                           or (open_packet and not ends))
        out.append(step)
    return out
