"""Which rules of the spec (fixtures/rules.toml) the suite can fail, per profile and
section.

A unit-role rule is *covered* on a profile when a case of the catalogue names it in its
``rules`` and applies to that profile (it is not MISSING there). Such a case FAILs a
target that breaks the rule (NON-STRICT for a ``[D]`` rule on a target that does not
implement the project's decisions, INFO for ``[D-info]``). Coverage is counted on the
embedded emulator, which has the test rig and allows destructive cases; on a real unit
those cases are COULD-NOT-TEST unless the run allows them.

The state x command x observer matrix `diff` runs (conformance/diff/matrix.py) is
counted beside them, per model, as the emulator runs it (rig and destructive commands
allowed): its cells run, those the model makes meaningless (listed as such), the
observers each cell reads, and the clauses of `[M]` rules that set or clear a status bit
without a cell that can fail them (conformance/diff/clauses.py).

Host-role rules are judged by the host certification's checks, not by cases: that
module registers each check with the rules it judges (:func:`register_host_check`), and
``coverage(role="host")`` counts them the same way.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from functools import cache

from gve_fixtures.profile import Profile, available_profiles, load_profile
from gve_fixtures.rules import Rule, load_rules

ROLES = ("unit", "host")

#: host check name -> the rule IDs it judges (filled by the host certification module)
HOST_CHECKS: dict[str, tuple[str, ...]] = {}


def register_host_check(name: str, rules: Iterable[str]) -> None:
    """Record that the host check ``name`` can fail ``rules`` (host-role rule IDs)."""
    rules = tuple(rules)
    known = load_rules()
    wrong = [r for r in rules if r not in known or "host" not in known[r].roles]
    if wrong:
        raise ValueError(f"host check {name}: not host-role rules of rules.toml: {wrong}")
    HOST_CHECKS[name] = rules


@dataclass
class SectionCoverage:
    section: str
    covered: dict[str, list[str]] = field(default_factory=dict)   # rule ID -> case IDs
    uncovered: list[str] = field(default_factory=list)            # rule IDs

    @property
    def total(self) -> int:
        return len(self.covered) + len(self.uncovered)


@dataclass
class MatrixCoverage:
    """The matrix on one model: cells (state x command form) run and left out (why: a
    state or form the model has not is meaningless there), the observers each reads at
    once, and the clauses that set or clear a status bit with no cell to fail them."""

    cells: int = 0
    run: int = 0
    observers: int = 0
    left_out: dict[str, list[str]] = field(default_factory=dict)   # why -> cell names
    clauses: int = 0
    lacking: list[str] = field(default_factory=list)        # clauses no cell can fail
    meaningless: list[str] = field(default_factory=list)    # clauses the model cannot show

    @property
    def meaningless_cells(self) -> int:
        return sum(len(names) for why, names in self.left_out.items()
                   if why.startswith("the "))

    def as_dict(self) -> dict:
        return {"cells": self.cells, "run": self.run, "observers": self.observers,
                "read": self.run * self.observers, "left_out": self.left_out,
                "meaningless_cells": self.meaningless_cells, "clauses": self.clauses,
                "lacking": self.lacking, "meaningless": self.meaningless}


@cache
def matrix_coverage(profile: str) -> MatrixCoverage:
    """The matrix on ``profile`` as the emulator runs it."""
    from conformance.diff.clauses import clauses, missing
    from conformance.diff.grammar import Options
    from conformance.diff.matrix import cells, observers

    p = load_profile(profile)
    every = cells(p, Options(destructive=True, rig=True), built=False)
    out = MatrixCoverage(cells=len(every), run=sum(1 for c in every if not c.left_out),
                         observers=len(observers(p)))
    for c in every:
        if c.left_out:
            out.left_out.setdefault(c.left_out, []).append(c.name)
    rules = load_rules()
    out.clauses = sum(1 for c in clauses()
                      if rules[c.rule].applies_to(p.name, p.family))
    lacking, meaningless = missing(p, every)
    out.lacking, out.meaningless = [str(c) for c in lacking], [str(c) for c in meaningless]
    return out


@dataclass
class ProfileCoverage:
    profile: str
    sections: list[SectionCoverage] = field(default_factory=list)
    matrix: MatrixCoverage | None = None

    @property
    def covered(self) -> int:
        return sum(len(s.covered) for s in self.sections)

    @property
    def total(self) -> int:
        return sum(s.total for s in self.sections)

    @property
    def uncovered(self) -> list[str]:
        return [r for s in self.sections for r in s.uncovered]

    def as_dict(self) -> dict:
        return {"profile": self.profile, "covered": self.covered, "total": self.total,
                "sections": [{"section": s.section, "covered": s.covered,
                              "uncovered": s.uncovered} for s in self.sections],
                "matrix": None if self.matrix is None else self.matrix.as_dict()}


def _judges(role: str, cases) -> list[tuple[str, tuple[str, ...], object]]:
    """(name, rule IDs, case or None) of everything that can fail rules of ``role``."""
    if role == "host":
        return [(name, rules, None) for name, rules in HOST_CHECKS.items()]
    return [(c.id, c.rules, c) for c in cases]


def coverage(profiles: Iterable[str] | None = None, *, role: str = "unit",
             cases=None) -> list[ProfileCoverage]:
    """Per profile, per section (in spec order), the rules of ``role`` with the cases
    (or host checks) that can fail them, and the rules without one. ``cases``: the
    catalogue's cases to count (default: all)."""
    if role not in ROLES:
        raise ValueError(f"role must be one of {ROLES}")
    if cases is None:
        from conformance.run.selection import select
        cases = select()
    rules = [r for r in load_rules().values() if role in r.roles]
    judges = _judges(role, cases)
    out = []
    for name in profiles or available_profiles():
        p = load_profile(name)
        result = ProfileCoverage(p.name)
        by_section: dict[str, SectionCoverage] = {}
        for rule in rules:
            if not rule.applies_to(p.name, p.family):
                continue
            s = by_section.setdefault(rule.section, SectionCoverage(rule.section))
            names = [n for n, ids, c in judges if rule.id in ids and _applies(c, p)]
            if names:
                s.covered[rule.id] = names
            else:
                s.uncovered.append(rule.id)
        result.sections = sorted(by_section.values(), key=lambda s: _order(s.section))
        if role == "unit":
            result.matrix = matrix_coverage(p.name)
        out.append(result)
    return out


def _applies(case, profile: Profile) -> bool:
    return case is None or case.missing_for(profile) is None


def _order(section: str) -> tuple[int, ...]:
    return tuple(int(p) for p in section.split("."))


def uncovered_rules(report: list[ProfileCoverage]) -> dict[str, list[str]]:
    """Rule ID -> the profiles on which nothing can fail it."""
    out: dict[str, list[str]] = {}
    for pc in report:
        for rule in pc.uncovered:
            out.setdefault(rule, []).append(pc.profile)
    return out


def format_coverage(report: list[ProfileCoverage], role: str = "unit") -> str:
    """The console table of ``gve-conformance --coverage``: covered/applicable rules per
    section and profile, then every rule nothing can fail, with the profiles."""
    rules: dict[str, Rule] = load_rules()
    sections = sorted({s.section for pc in report for s in pc.sections}, key=_order)
    names = [pc.profile for pc in report]
    width = max(9, *(len(n) for n in names))
    lines = [f"Rules of the spec ({role} role) with a case that can fail them, "
             "per section and profile (covered/applicable):", "",
             "section " + " ".join(f"{n:>{width}}" for n in names)]
    for sec in sections:
        cells = []
        for pc in report:
            s = next((s for s in pc.sections if s.section == sec), None)
            cells.append("-" if s is None else f"{len(s.covered)}/{s.total}")
        lines.append(f"{sec:<8}" + " ".join(f"{c:>{width}}" for c in cells))
    lines.append(f"{'total':<8}" + " ".join(f"{f'{pc.covered}/{pc.total}':>{width}}"
                                              for pc in report))
    missing = uncovered_rules(report)
    lines += _format_matrix(report)
    lines.append("")
    if not missing:
        lines.append("Every rule is covered on every profile it applies to.")
    else:
        lines.append(f"{len(missing)} rule(s) without a case that can fail them:")
        for rule_id, where in missing.items():
            on = "every profile" if len(where) == len(report) else ", ".join(where)
            lines.append(f"  {rule_id} [{rules[rule_id].tag}] on {on}: {rules[rule_id].text}")
    return "\n".join(lines)


def _format_matrix(report: list[ProfileCoverage]) -> list[str]:
    """The matrix's part of the console table: per model, cells run of all, the
    observers each reads, the state x command x observer reads; then the cells left out,
    by why (meaningless on the model, or not sent by this run), and the clauses setting
    or clearing a status bit that no cell can fail."""
    shown = [pc for pc in report if pc.matrix is not None]
    if not shown:
        return []
    width = max(9, *(len(pc.profile) for pc in shown))
    rows = (("cells", lambda m: f"{m.run}/{m.cells}"),
            ("observed", lambda m: str(m.observers)),
            ("reads", lambda m: str(m.run * m.observers)),
            ("clauses", lambda m: f"{m.clauses - len(m.lacking) - len(m.meaningless)}"
                                  f"/{m.clauses}"))
    lines = ["", "The state x command x observer matrix diff runs, per model (cells run/all, "
             "observers read after each, state x command x observer reads, clauses setting "
             "or clearing a status bit with a cell that can fail them):", "",
             "matrix  " + " ".join(f"{pc.profile:>{width}}" for pc in shown)]
    lines += [f"{title:<8}" + " ".join(f"{value(pc.matrix):>{width}}" for pc in shown)
              for title, value in rows]
    for pc in shown:
        m = pc.matrix
        for why, names in sorted(m.left_out.items()):
            kind = "meaningless" if why.startswith("the ") else "not run"
            lines.append(f"  {pc.profile}: {len(names)} cell(s) {kind} ({why}): "
                         f"{_cells_named(names)}")
        for clause in m.lacking:
            lines.append(f"  {pc.profile}: no cell can fail {clause}")
        for clause in m.meaningless:
            lines.append(f"  {pc.profile}: meaningless on the model: {clause}")
    return lines


def _cells_named(names: list[str]) -> str:
    """Cells named compactly: a state whose every form is left out by its state name."""
    by_state: dict[str, list[str]] = {}
    for n in names:
        state, _, form = n.partition(" x ")
        by_state.setdefault(state, []).append(form)
    return "; ".join(f"{state} x {', '.join(forms)}" if len(forms) <= 6
                     else f"{state} x every form ({len(forms)})"
                     for state, forms in by_state.items())
