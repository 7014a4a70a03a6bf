"""A check judges and reports the same observation: no ``expect(...)`` of a case
evaluates a reading twice, once in its condition and again for ``observed=`` (a second
`PF` of a moving unit, a second look of the rig, may differ from the one judged). A case
reads once into a name, or uses ``expect_equal(observed, expected, ...)``. Calls of
builtins (``len``, ``sorted``) read nothing of the unit and are not looked at."""

from __future__ import annotations

import ast
import builtins
from pathlib import Path

CASES = Path(__file__).parents[3] / "conformance" / "cases"


def _reads(node: ast.AST) -> set[str]:
    """The calls within ``node`` that may read something, as source."""
    return {ast.unparse(n) for n in ast.walk(node) if isinstance(n, ast.Call)
            and not (isinstance(n.func, ast.Name) and hasattr(builtins, n.func.id))}


def read_twice(source: str) -> list[tuple[int, str]]:
    """Each ``expect(...)`` of ``source`` whose condition and ``observed=`` make the same
    call: its line and the call."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if not (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
                and node.func.attr == "expect" and node.args):
            continue
        for keyword in node.keywords:
            if keyword.arg == "observed":
                found += [(node.lineno, call) for call in
                          sorted(_reads(node.args[0]) & _reads(keyword.value))]
    return found


def test_no_check_of_a_case_reads_its_observation_twice():
    twice = {f"{path.name}:{line}": call for path in sorted(CASES.glob("*.py"))
             for line, call in read_twice(path.read_text(encoding="utf-8"))}
    assert twice == {}


def test_the_scan_finds_a_reading_judged_and_reported_apart():
    twice = "ctx.expect(position(ctx) == want, 'x', observed=position(ctx))\n"
    once = ("here = position(ctx)\nctx.expect(here == want, 'x', observed=here)\n"
            "ctx.expect_equal(position(ctx), want, 'x')\n"
            "ctx.expect(len(r) > 1, 'x', observed=f'{len(r)} rates')\n")
    assert read_twice(twice) == [(1, "position(ctx)")]
    assert read_twice(once) == []
