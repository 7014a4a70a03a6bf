"""The suite's command facts live in the catalogue: no module of the suite outside
conformance/protocol defines (at module or class level) a collection of two or more
command names of its own."""

from __future__ import annotations

import ast
from pathlib import Path

from conformance.protocol.catalogue import catalogue

SUITE = Path(__file__).parents[3] / "conformance"


def _literal_name_sets(source: str, names: set[str]) -> list[tuple[int, list[str]]]:
    tree = ast.parse(source)
    statements = [*tree.body, *(s for c in tree.body if isinstance(c, ast.ClassDef)
                                for s in c.body)]
    found = []
    for s in statements:
        if not isinstance(s, ast.Assign | ast.AnnAssign) or s.value is None:
            continue
        for node in ast.walk(s.value):
            if isinstance(node, ast.Tuple | ast.List | ast.Set):
                values = [e.value for e in node.elts
                          if isinstance(e, ast.Constant) and isinstance(e.value, str)]
                if len(values) == len(node.elts) >= 2 and set(values) <= names:
                    found.append((node.lineno, values))
    return found


def test_no_module_of_the_suite_keeps_its_own_command_names():
    names = set(catalogue())
    found = [f"{path.relative_to(SUITE.parent)}:{line}: {values}"
             for path in sorted(SUITE.rglob("*.py")) if "protocol" not in path.parts
             for line, values in _literal_name_sets(path.read_text(encoding="utf-8"), names)]
    assert found == []


def test_the_scan_finds_a_set_of_command_names():
    source = ('MOTION = frozenset({"L", "C"})\nONE = ("L",)\nWORDS = ("L", "word")\n'
              'class K:\n    MEMBERS = ["C", "B"]\n')
    assert _literal_name_sets(source, set(catalogue())) == [(1, ["L", "C"]), (5, ["C", "B"])]
