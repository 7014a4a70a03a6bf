"""Every check names its rule (docs/suite.md, "A case"): a check that names none is a
defect of the suite, an ERROR when it is recorded. A run meets only the checks it reaches,
so a check on a path only a broken unit takes (a refusal where an answer was due) is
found here by reading the catalogue's source: in a case that names more than one rule,
every call that records a check passes ``rule=``; so does every helper that records one
without taking the rule from its caller."""

from __future__ import annotations

import ast
import inspect
from pathlib import Path

import conformance.cases
from conformance.cases import _kit

CASES = Path(conformance.cases.__file__).parent


def _recorders() -> set[str]:
    """What records a check: ``ctx.expect`` and every helper of the kit taking ``rule``."""
    return {"expect"} | {name for name, f in inspect.getmembers(_kit, inspect.isfunction)
                         if "rule" in inspect.signature(f).parameters}


def _rule_count(fn: ast.FunctionDef) -> int | None:
    """How many rules a case function's ``@case`` names (None: not a case)."""
    for d in fn.decorator_list:
        if isinstance(d, ast.Call) and getattr(d.func, "id", "") == "case":
            for kw in d.keywords:
                if kw.arg == "rules" and isinstance(kw.value, ast.Tuple):
                    return len(kw.value.elts)
    return None


def _unnamed(recorders: set[str], folder: Path = CASES) -> list[str]:
    out = []
    for path in sorted(folder.glob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for fn in tree.body:
            if not isinstance(fn, ast.FunctionDef):
                continue
            rules = _rule_count(fn)
            takes_rule = "rule" in {a.arg for a in fn.args.args + fn.args.kwonlyargs}
            if rules == 1 or (rules is None and takes_rule):
                continue
            for node in ast.walk(fn):
                if not isinstance(node, ast.Call):
                    continue
                f = node.func
                name = f.attr if isinstance(f, ast.Attribute) else getattr(f, "id", "")
                named = any(k.arg in ("rule", None) for k in node.keywords)
                if name in recorders and not named:
                    out.append(f"{path.name}:{node.lineno} {fn.name}: {name}(...)")
    return out


def test_every_check_of_a_case_with_several_rules_names_its_rule():
    assert _unnamed(_recorders()) == []


def test_the_reading_finds_a_check_on_a_failure_path_without_its_rule(tmp_path):
    (tmp_path / "s99_toy.py").write_text(
        "@case('99.toy', rules=('5.code.ok', '8.index.counts'))\n"
        "def toy(ctx):\n"
        "    if ctx.link.send('?') is None:\n"
        "        ctx.expect(False, 'no answer')\n"
        "    ctx.expect(True, 'named', rule='5.code.ok')\n", encoding="utf-8")
    assert _unnamed({"expect"}, tmp_path) == ["s99_toy.py:4 toy: expect(...)"]
