"""A disagreement labelled with the rule it touches (``labels.toml``) and graded by that
rule's tag, as the suite grades a failed check (M, M-ex: FAIL; D: NON-STRICT, or FAIL
on a profile that implements the project's decisions; D-info: INFO); a disagreement
touching no known rule is INFO. Where the spec allows both answers (``[[allowed]]`` in
the same file) the two sides differ without either being wrong: no finding, the
sequence ends there (the states differ from then on)."""

from __future__ import annotations

import tomllib
from dataclasses import dataclass
from functools import cache
from pathlib import Path

from conformance.protocol.parse import parse
from conformance.verdicts.verdict import INFO, grade
from gve_fixtures.rules import load_rules

LABELS_FILE = Path(__file__).with_name("labels.toml")
_FIELDS = ("command", "kind", "context", "earlier", "reference", "target", "family")



def command_of(body: str) -> str:
    """The class of a frame's command as every reader of the suite reads it (spec 10's
    name, `SW6` for a write of ST6), "" when none matches."""
    return parse(body).key


@dataclass(frozen=True)
class Label:
    rule: str
    conditions: dict

    def matches(self, facts: dict) -> bool:
        for key, wanted in self.conditions.items():
            if key == "context":
                if not set(wanted) <= facts["context"]:
                    return False
            elif key == "earlier":
                if not set(wanted) & facts["earlier"]:
                    return False
            elif facts[key] not in wanted:
                return False
        return True


@cache
def load_labels(path: Path = LABELS_FILE) -> tuple[Label, ...]:
    raw = tomllib.loads(path.read_text(encoding="utf-8"))
    rules = load_rules()
    out = []
    for i, entry in enumerate(raw.get("label", [])):
        rule = entry.get("rule")
        if rule not in rules:
            raise ValueError(f"{path.name}: label #{i + 1}: unknown rule {rule!r}")
        out.append(Label(rule, _conditions(path, f"label #{i + 1}", entry, "rule")))
    return tuple(out)


@cache
def load_allowed(path: Path = LABELS_FILE) -> tuple[Label, ...]:
    """The differences the spec allows both ways; ``rule`` holds why (the spec's words)."""
    raw = tomllib.loads(path.read_text(encoding="utf-8"))
    out = []
    for i, entry in enumerate(raw.get("allowed", [])):
        if not entry.get("why"):
            raise ValueError(f"{path.name}: allowed #{i + 1}: no why")
        out.append(Label(entry["why"], _conditions(path, f"allowed #{i + 1}", entry, "why")))
    return tuple(out)


def _conditions(path: Path, where: str, entry: dict, name: str) -> dict:
    unknown = set(entry) - {name, *_FIELDS}
    if unknown:
        raise ValueError(f"{path.name}: {where}: unknown field(s) {sorted(unknown)}")
    return {k: entry[k] for k in _FIELDS if k in entry}


def label(command: str, kind: str, context: set[str], earlier: set[str],
          reference: int | None, target: int | None = None,
          family: str | None = None) -> str | None:
    """The rule a disagreement touches (None: no known rule); ``reference`` and
    ``target`` are the two sides' error codes (None: no answer), ``family`` the
    profile's (GVE54, GVE84, GVE114)."""
    facts = {"command": command, "kind": kind, "context": context, "earlier": earlier,
             "reference": reference, "target": target, "family": family}
    for entry in load_labels():
        if entry.matches(facts):
            return entry.rule
    return None


def allowed(command: str, kind: str, context: set[str], earlier: set[str],
            reference: int | None, target: int | None,
            family: str | None = None) -> str | None:
    """Why the spec allows both answers (None: it does not); the fields as :func:`label`."""
    facts = {"command": command, "kind": kind, "context": context, "earlier": earlier,
             "reference": reference, "target": target, "family": family}
    for entry in load_allowed():
        if entry.matches(facts):
            return entry.rule
    return None


def verdict_of(rule: str | None, strict: bool) -> tuple[str, str]:
    """(verdict, tag) of a disagreement touching ``rule``."""
    if rule is None:
        return INFO, "D-info"
    tag = load_rules()[rule].tag
    return grade(tag, strict), tag
