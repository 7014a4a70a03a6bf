"""The state x command x observer matrix (``matrix.toml``): derived from the catalogue,
the manuals' worked examples and the profile, not written cell by cell.

A *cell* is one command form sent in one state: the state's steps, the form, every
observer the profile has read at once, then again at rest (and in a state holding
vectors, what `G` makes of them). The forms of a command are the catalogue's examples of
it and every frame of it in a worked example of the profile's family. A cell the profile
or the run cannot send (a destructive form without --allow-destructive, a state that
needs a rig input without a rig, checksum mode on a unit without checksums) is *left
out* with why: the matrix says how many cells it has, ran and left out, and which.
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass
from functools import cache
from pathlib import Path

from conformance.diff.grammar import Grammar, Options
from conformance.diff.labels import command_of
from conformance.diff.steps import Step
from conformance.protocol.catalogue import catalogue
from gve_fixtures import golden_transcripts
from gve_fixtures.profile import Profile
from gve_fixtures.transcript import load

MATRIX_FILE = Path(__file__).with_name("matrix.toml")


@dataclass(frozen=True)
class Cell:
    """One command form in one state: its steps, or why it is left out."""

    state: str
    form: str
    steps: tuple[Step, ...] = ()
    left_out: str = ""

    @property
    def name(self) -> str:
        return f"{self.state} x {self.form}"

    @property
    def meaningless(self) -> bool:
        """A cell the model makes meaningless (a state or a form it does not have), as
        against one this run could not send."""
        return self.left_out.startswith("the ")


@cache
def worked_forms(family: str) -> dict[str, list[str]]:
    return _worked_forms(family)


@cache
def load_matrix(path: Path = MATRIX_FILE) -> dict:
    return tomllib.loads(path.read_text(encoding="utf-8"))


def states(profile: Profile) -> list[tuple[str, list[str] | None]]:
    """The states of the matrix this profile distinguishes: the file's (None: a state the
    model has not), then one per micro-step mode and current setting the profile lists
    (its reset mode is `idle`)."""
    m = load_matrix()
    one = profile.high_mask & -profile.high_mask
    places = {"high_one": "%02X" % one, "high_grounded": "%02X" % (0xFF ^ one)}
    # a state that needs an interrupt input behind ST1 the model lacks: none (no such state)
    out = [(s["name"], [f.format(**places) for f in s["steps"]]
            if one or not any("{high_" in f for f in s["steps"]) else None)
           for s in m["state"]]
    ms = profile.microstep
    if ms is not None:
        out += [(f"mode-{mode}", [f.format(mode=mode) for f in m["microstep"]["mode"]])
                for mode in ms.factors if mode != ms.reset_mode]
        out += [(f"current-{c}", [f.format(current=c) for f in m["microstep"]["current"]])
                for c in ms.currents if c != ms.reset_current]
    return out


def _worked_forms(family: str) -> dict[str, list[str]]:
    """The frames of the worked examples of ``family`` (fixtures/transcripts), by command:
    the syntax its manual shows (frames sent in checksum mode are left out: their last
    field is a checksum, not a form)."""
    out: dict[str, list[str]] = {}
    for path in golden_transcripts():
        t = load(path)
        if family not in t.meta.get("profiles", "").split():
            continue
        summed = False
        for rec in t.records:
            if rec.direction != ">":
                continue
            text = rec.data.decode("latin-1").rstrip("\r")
            body = text[2:] if text.startswith("!") and len(text) > 2 else text
            if body.startswith("%+"):
                summed = True
            elif body.startswith("%-"):
                summed = False
            elif not summed and command_of(body):
                out.setdefault(command_of(body), []).append(body)
    return out


def forms(profile: Profile, names: list[str]) -> list[str]:
    """Every form of every command of ``names``: the catalogue's examples, then the worked
    examples' frames, each once, in the catalogue's order."""
    worked = worked_forms(profile.family)
    seen: set[str] = set()
    out = []
    for name, c in catalogue().items():
        if (c.known_as if name != "SW6" else "SW") not in names:
            continue
        for body in (*c.examples, *worked.get(name, ()), *_alone(profile, name)):
            if body not in seen:
                seen.add(body)
                out.append(body)
    return out


def _alone(profile: Profile, name: str) -> list[str]:
    """A vector of ``name`` moving each axis alone (`L0,0,0,100`: the GVE114's A too)."""
    if name not in load_matrix()["forms"]["alone"]:
        return []
    n = len(profile.axes)
    return [name + ",".join("100" if i == j else "0" for j in range(n)) for i in range(n)]


def cells(profile: Profile, options: Options, *, built: bool = True) -> list[Cell]:
    """Every cell of the matrix on ``profile`` under ``options``: those it can send with
    their steps (``built``; else none: a census of what runs), the others with why they
    are left out."""
    m = load_matrix()
    grammar = Grammar(profile, options)
    every = Grammar(profile, Options(destructive=True, rig=True))
    observers = [o for o in m["observers"]["now"] if grammar.written.can([o])]
    rest = [o for o in m["observers"]["rest"] if grammar.written.can([o])]
    held = [o for o in m["observers"]["held"] if grammar.written.can([o])]
    move = [o for o in m["observers"]["move"] if grammar.written.can([o])]
    spindle = profile.spindle
    out = []
    for state, setup in states(profile):
        lines_after = observers + rest + (held if state in m["observers"]["held_states"]
                                          else []) + move
        for form in forms(profile, every.names):
            out.append(_cell(grammar, every, state, setup, form, lines_after, built))
        if spindle is not None and state == "idle":
            for form in forms(profile, [n for n in every.names if n in spindle.commands]):
                out.append(_cell(grammar, every, "spindle", [], f"spindle:{form}",
                                 observers + rest + move, built))
    return out


def _cell(grammar: Grammar, every: Grammar, state: str, setup: list[str] | None, form: str,
          after: list[str], built: bool = True) -> Cell:
    if setup is None or not every.written.can(setup):
        return Cell(state, form, left_out=f"the {every.profile.family} has no such state")
    lines = [*setup, form, *after]
    if not every.written.can(lines):
        return Cell(state, form, left_out=f"the {every.profile.family} cannot send it")
    if not grammar.written.can(lines):
        why = ("needs a test rig" if any(x.startswith("input ") for x in setup)
               else "needs --allow-destructive")
        return Cell(state, form, left_out=why)
    return Cell(state, form, tuple(grammar.idiom(lines)) if built else ())


def observers(profile: Profile) -> list[str]:
    """The observers the matrix reads at once after each command on ``profile`` (the rig's
    `state` among them)."""
    every = Grammar(profile, Options(destructive=True, rig=True))
    return [o for o in load_matrix()["observers"]["now"] if every.written.can([o])]


def summary(all_cells: list[Cell]) -> str:
    """How many cells the matrix has on a profile, how many run and why the others do not."""
    ran = sum(1 for c in all_cells if not c.left_out)
    why: dict[str, int] = {}
    for c in all_cells:
        if c.left_out:
            why[c.left_out] = why.get(c.left_out, 0) + 1
    rest = "; ".join(f"{n} {w}" for w, n in sorted(why.items()))
    return f"matrix: {ran} of {len(all_cells)} cells" + (f" (left out: {rest})" if rest else "")
