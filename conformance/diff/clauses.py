"""The clauses of the `[M]` rules that say a command sets or clears a status bit
(fixtures/rules.toml, the bits of ST6 by their names in fixtures, ST4/ST5 the cause
words), and the matrix cell that can fail each: the command sent in a state where the bit
stands the other way (matrix.toml's `bits`), then the word read at once (every cell
reads the observers of matrix.toml's `now` right after its command).

A clause is read off the rule's text: the command is its first one in backticks (an
input where the text speaks of one and names no command), the verb `sets` or `clears`,
and the bits right after the verb (`ST4..ST6` a range of words, "its cause bit" ST4 or
ST5). A clause without such a cell on a model where its rule applies is listed by
:func:`missing` (``gve-conformance --coverage`` prints them).
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from conformance.diff.grammar import Grammar, Options
from conformance.diff.labels import command_of
from conformance.diff.matrix import Cell, load_matrix, observers, states
from gve_fixtures.profile import Profile
from gve_fixtures.protocol import St6
from gve_fixtures.rules import load_rules

#: the status bits a clause may name: ST6's by name, the words themselves
_BIT = "|".join([*St6.__members__, r"ST[0-6](?:\.\.ST[0-6])?", "its cause bit"])
_CLAUSE = re.compile(r"\b(sets?|clears?)\s+((?:(?:%s)(?:\s*,\s*|\s+and\s+|\s+)?)+)" % _BIT)
_ONE = re.compile(_BIT)
#: the commands a state's bits are read with at once, by the word they are in
_READ = {6: ("SR6", "F"), 4: ("SR4",), 5: ("SR5",)}
#: forms that read and change nothing: what an input's clause is read after
_READS = tuple(load_matrix()["reads_alone"])


@dataclass(frozen=True)
class Clause:
    rule: str
    command: str          # a command's name, or "input" (the rig's)
    sets: bool            # sets (True) or clears (False)
    bit: str              # an ST6 bit's name, "ST4".."ST6", or "cause" (ST4 or ST5)

    def __str__(self) -> str:
        verb = "sets" if self.sets else "clears"
        return f"{self.rule}: {self.command} {verb} {self.bit}"


def clauses() -> list[Clause]:
    """Every clause of every `[M]` rule that says a command sets or clears a status bit."""
    out = []
    for rule in load_rules().values():
        if rule.tag != "M":
            continue
        named = re.search(r"`([^`]+)`", rule.text)
        command = command_of(named.group(1)) if named else (
            "input" if "input" in rule.text else "")
        if not command:
            continue
        for m in _CLAUSE.finditer(rule.text):
            for bit in _bits(m.group(2)):
                out.append(Clause(rule.id, command, m.group(1).startswith("set"), bit))
    return list(dict.fromkeys(out))


def _bits(text: str) -> list[str]:
    out = []
    for token in _ONE.findall(text):
        if token == "its cause bit":
            out.append("cause")
        elif ".." in token:
            lo, hi = (int(t[2]) for t in token.split(".."))
            out += [f"ST{n}" for n in range(lo, hi + 1)]
        else:
            out.append(token)
    return out


def _words(bit: str) -> list[int]:
    """The status words a bit is read in."""
    if bit == "cause":
        return [4, 5]
    return [int(bit[2])] if bit.startswith("ST") else [6]


def _stands(bit: str, state_bits: set[str]) -> bool:
    """Whether ``bit`` is set in a state whose set bits are ``state_bits``."""
    if bit == "cause":
        return bool({"ST4", "ST5"} & state_bits)
    if bit == "ST6":
        return bool(set(St6.__members__) & state_bits)
    return bit in state_bits


def _state_bits() -> dict[str, set[str]]:
    return {s["name"]: set(s.get("bits", [])) for s in load_matrix()["state"]}


def covering(clause: Clause, all_cells: list[Cell], reads: list[str]) -> Cell | None:
    """A cell of ``all_cells`` that can fail ``clause`` (None: none): the command sent
    where the bit stands the other way, the bit's word read right after it (``reads``:
    what the matrix reads at once after each command on the model); for an input's
    clause, a read that changes nothing in a state an input left with the bit set."""
    if not any(body in _READ.get(w, ()) for w in _words(clause.bit) for body in reads):
        return None
    bits = _state_bits()
    for cell in all_cells:
        if cell.left_out or cell.state not in bits:
            continue
        before = bits[cell.state]
        if clause.command == "input":
            if not (_stands(clause.bit, before) and cell.form in _READS
                    and any(w.startswith("input") for w in _setup(cell))):
                continue
        elif command_of(cell.form) != clause.command or _stands(clause.bit, before) \
                == clause.sets:
            continue
        return cell
    return None


def _setup(cell: Cell) -> list[str]:
    return next((list(s["steps"]) for s in load_matrix()["state"]
                 if s["name"] == cell.state), [])


def missing(profile: Profile, all_cells: list[Cell]) -> tuple[list[Clause], list[Clause]]:
    """The clauses of rules that apply to ``profile`` without a cell among ``all_cells``
    that can fail them: those the matrix lacks, and those the model makes meaningless
    (the bit never stands so in a state it has: the GVE84 has no input behind ST1)."""
    rules = load_rules()
    bits = _state_bits()
    reads = observers(profile)
    every = Grammar(profile, Options(destructive=True, rig=True))
    has = {name for name, setup in states(profile)
           if setup is not None and every.written.can(setup)}
    lacking, meaningless = [], []
    for c in clauses():
        if not rules[c.rule].applies_to(profile.name, profile.family) or \
                covering(c, all_cells, reads) is not None:
            continue
        possible = [s for s, b in bits.items() if _stands(c.bit, b) != c.sets
                    or c.command == "input"]
        (lacking if any(s in has for s in possible) else meaningless).append(c)
    return lacking, meaningless
