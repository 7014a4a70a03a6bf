"""No class of the suite is over 400 lines (its docstring and comments count): a class
that large holds more than one job, and a newcomer must read all of it to change one.
Measured with ``ast`` from a class's first line to its last.

The classes still over it are listed with the size they may not exceed: the test fails
when one grows, and when one is cut to the limit (then its line goes)."""

from __future__ import annotations

import ast
from pathlib import Path

SUITE = Path(__file__).parents[2] / "conformance"
LIMIT = 400

#: classes over the limit, by module and name: the most lines each may keep until cut
OVER: dict[tuple[str, str], int] = {}


def _sizes() -> dict[tuple[str, str], int]:
    sizes = {}
    for path in sorted(SUITE.rglob("*.py")):
        module = path.relative_to(SUITE).as_posix()
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ClassDef):
                sizes[module, node.name] = node.end_lineno - node.lineno + 1
    return sizes


def test_no_class_of_the_suite_is_over_the_limit():
    sizes = _sizes()
    over = {key: n for key, n in sizes.items() if n > OVER.get(key, LIMIT)}
    assert over == {}, f"classes over {LIMIT} lines (or grown past their listed size): {over}"
    cut = [key for key in OVER if sizes.get(key, 0) <= LIMIT]
    assert cut == [], f"cut to {LIMIT} lines or gone: take them off OVER: {cut}"


def test_the_measure_counts_a_class_from_its_first_line_to_its_last():
    source = "class A:\n    '''Doc.'''\n\n    def f(self):\n        return 1\n"
    (node,) = ast.parse(source).body
    assert node.end_lineno - node.lineno + 1 == 5
