"""The suite's command facts live in the catalogue: no module of the suite outside
conformance/protocol keeps a collection of two or more command names of its own — at
module or class level, nor inside a function as a membership test (``x in ("L", "C")``)
or assigned to a name. A list of frames a case sends (``for body in ("D", "K")``, a
script) is data, not a fact about commands, and is not looked at."""

from __future__ import annotations

import ast
from pathlib import Path

from conformance.protocol.catalogue import catalogue

SUITE = Path(__file__).parents[3] / "conformance"


def _names_in(node: ast.AST, names: set[str]) -> list[str] | None:
    """The names of a literal tuple, list or set made only of two or more command names."""
    if not isinstance(node, ast.Tuple | ast.List | ast.Set):
        return None
    values = [e.value for e in node.elts
              if isinstance(e, ast.Constant) and isinstance(e.value, str)]
    return values if len(values) == len(node.elts) >= 2 and set(values) <= names else None


def _collections(value: ast.AST, names: set[str]) -> list[tuple[int, list[str]]]:
    return [(n.lineno, v) for n in ast.walk(value) if (v := _names_in(n, names))]


_MAKERS = {"frozenset", "set", "tuple", "list", "sorted"}


def _held(value: ast.AST, names: set[str]) -> list[tuple[int, list[str]]]:
    """A collection of names a function keeps: the value assigned itself, made into a set
    (``frozenset(("L", "C"))``) or filtered (``[n for n in ("L", "C") if ...]``) — not
    frames passed on to a call (``x = link.send_each(["H", "D"])``)."""
    if isinstance(value, ast.Call) and isinstance(value.func, ast.Name) \
            and value.func.id in _MAKERS and value.args:
        value = value.args[0]
    if isinstance(value, ast.ListComp | ast.SetComp | ast.GeneratorExp):
        return [(g.iter.lineno, v) for g in value.generators
                if g.ifs and (v := _names_in(g.iter, names))]
    v = _names_in(value, names)
    return [(value.lineno, v)] if v else []


def _literal_name_sets(source: str, names: set[str]) -> list[tuple[int, list[str]]]:
    tree = ast.parse(source)
    statements = [*tree.body, *(s for c in tree.body if isinstance(c, ast.ClassDef)
                                for s in c.body)]
    found = []
    for s in statements:
        if isinstance(s, ast.Assign | ast.AnnAssign) and s.value is not None:
            found += _collections(s.value, names)
    inside = {n for f in ast.walk(tree)
              if isinstance(f, ast.FunctionDef | ast.AsyncFunctionDef | ast.Lambda)
              for n in ast.walk(f)}
    for node in inside:
        if isinstance(node, ast.Compare):
            found += [(node.lineno, v) for op, c in zip(node.ops, node.comparators, strict=True)
                      if isinstance(op, ast.In | ast.NotIn) and (v := _names_in(c, names))]
        elif isinstance(node, ast.Assign | ast.AnnAssign | ast.AugAssign | ast.NamedExpr) \
                and node.value is not None:
            found += _held(node.value, names)
    return [(line, list(v)) for line, v in sorted({(ln, tuple(v)) for ln, v in found})]


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


def test_the_scan_finds_command_names_kept_inside_a_function():
    source = ('def f(name, link):\n'
              '    if name in ("L", "C"):\n'                 # 2: a membership test
              '        pass\n'
              '    if name not in ["D", "K"]:\n'             # 4: its negation
              '        pass\n'
              '    stops = {"H", "SW6"}\n'                   # 6: assigned to a name
              '    picks = [n for n in ("C", "B") if n]\n'   # 7: filtered, assigned
              '    ok = name in ("L",) or name == "C"\n'     # 8: one name: a dispatch
              '    tags = tag in ("M", "M-ex")\n'            # 9: not all command names
              '    return lambda n: n in ("XA", "XU")\n')    # 10: inside a lambda
    assert _literal_name_sets(source, set(catalogue())) == [
        (2, ["L", "C"]), (4, ["D", "K"]), (6, ["H", "SW6"]), (7, ["C", "B"]),
        (10, ["XA", "XU"])]


def test_the_scan_leaves_frames_sent_alone():
    source = ('def case(ctx):\n'
              '    for body in ("D", "K", "R"):\n'           # frames a case sends
              '        ctx.link.send(body)\n'
              '    ctx.link.send_each(["SR0", "@", "SR0"])\n'
              '    probe.run(["H", "G"])\n'                  # a script, passed on
              '    r = ctx.link.send_each(["H", "D"])\n'     # frames, their answers kept
              '    frames = [f"!0{b}" for b in ("H", "G")]\n'
              '    return [ctx.link.send(b) for b in ("H", "G")]\n')
    assert _literal_name_sets(source, set(catalogue())) == []
