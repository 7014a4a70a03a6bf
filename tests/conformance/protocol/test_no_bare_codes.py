"""The suite names the protocol's error codes: no module of the suite outside
conformance/protocol (nor of the reference host, gve_host) compares an answer's code with
a bare number, hands one to the cases' `code()` check, or returns one where its function
says an ErrorCode comes back.

What counts as a code is decided by name, so that bit masks, counts and byte values never
match: an operand named ``code`` (``r.code``, ``ex.code``, a local ``code``; not
``exit_code``) compared by ``==``, ``!=``, ``in`` or ``not in`` (also inside a tuple
comparison such as ``(r.code, r.values) == (1, ["2"])``) with an int literal, a
collection of int literals or a conditional choosing one; the ``value`` of
``code(ctx, r, value, ...)``; and a ``return`` of an int literal in a function annotated
to return an ``ErrorCode`` (or a tuple whose first element is one, such as ``(code, k)``)."""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).parents[3]
SUITE = ROOT / "conformance"
HOST = ROOT / "gve_host"
EQUALITY = (ast.Eq, ast.NotEq, ast.In, ast.NotIn)


def _literal(node: ast.expr) -> bool:
    """An int literal, a collection of them, or a conditional choosing one."""
    if isinstance(node, ast.Constant):
        return type(node.value) is int
    if isinstance(node, ast.Tuple | ast.List | ast.Set):
        return bool(node.elts) and all(_literal(e) for e in node.elts)
    if isinstance(node, ast.IfExp):
        return _literal(node.body) or _literal(node.orelse)
    return False


def _named_code(node: ast.expr) -> bool:
    return (isinstance(node, ast.Name) and node.id == "code") or \
        (isinstance(node, ast.Attribute) and node.attr == "code")


def _pairs(node: ast.Compare):
    """The (left, right) operands of each equality or membership test in ``node``;
    equal-length tuples compared with each other, element by element."""
    operands = [node.left, *node.comparators]
    for op, left, right in zip(node.ops, operands, operands[1:], strict=False):
        if not isinstance(op, EQUALITY):
            continue
        if isinstance(left, ast.Tuple) and isinstance(right, ast.Tuple) and \
                len(left.elts) == len(right.elts):
            yield from zip(left.elts, right.elts, strict=True)
        else:
            yield left, right


def _returns_code(function: ast.FunctionDef | ast.AsyncFunctionDef) -> str | None:
    """"whole" when the function is annotated to return an ErrorCode, "first" when a
    tuple whose first element is one, else None."""
    note = function.returns
    if note is None:
        return None
    if isinstance(note, ast.BinOp):                 # ErrorCode | None
        note = note.left
    if isinstance(note, ast.Name) and note.id == "ErrorCode":
        return "whole"
    if isinstance(note, ast.Subscript) and isinstance(note.value, ast.Name) and \
            note.value.id == "tuple" and isinstance(note.slice, ast.Tuple) and \
            note.slice.elts and isinstance(note.slice.elts[0], ast.Name) and \
            note.slice.elts[0].id == "ErrorCode":
        return "first"
    return None


def _own_returns(function: ast.FunctionDef | ast.AsyncFunctionDef):
    """The return statements of ``function`` itself, not of functions inside it."""
    todo = list(function.body)
    while todo:
        node = todo.pop()
        if isinstance(node, ast.Return):
            yield node
        elif not isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.Lambda |
                            ast.ClassDef):
            todo.extend(ast.iter_child_nodes(node))


def bare_codes(source: str) -> list[tuple[int, str]]:
    """(line, text) of every bare error-code number in ``source``."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Compare):
            if any((_named_code(a) and _literal(b)) or (_named_code(b) and _literal(a))
                   for a, b in _pairs(node)):
                found.append((node.lineno, ast.unparse(node)))
        elif isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and \
                node.func.id == "code":
            value = node.args[2] if len(node.args) > 2 else next(
                (k.value for k in node.keywords if k.arg == "value"), None)
            if value is not None and _literal(value):
                found.append((node.lineno, ast.unparse(node)))
        elif isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            shape = _returns_code(node)
            for r in _own_returns(node) if shape else ():
                value = r.value
                if shape == "first" and isinstance(value, ast.Tuple) and value.elts:
                    value = value.elts[0]
                if value is not None and _literal(value):
                    found.append((r.lineno, ast.unparse(r)))
    return sorted(found)


def test_the_suite_names_its_error_codes():
    paths = [*(p for p in SUITE.rglob("*.py") if "protocol" not in p.relative_to(SUITE).parts),
             *HOST.rglob("*.py")]
    found = [f"{path.relative_to(ROOT)}:{line}: {text}" for path in sorted(paths)
             for line, text in bare_codes(path.read_text(encoding="utf-8"))]
    assert len(paths) > 50
    assert found == []


PLANTED = '''\
ok = r is not None and r.code == 0
if code in (1, 7):
    pass
busy = ex.code != (1 if full else 0)
both = (r.code, r.values) == (1, ["2"])
code(ctx, r, 4, "a wrong checksum")
code(ctx, r, value=5, what="out of range")


def end_packet(n: int) -> tuple[ErrorCode, int]:
    if n:
        return 2, n
    return ErrorCode.OK, 0


def checksum_answer(state: str) -> ErrorCode:
    return 0 if state == "good" else ErrorCode.SYNTAX


# none of these is a code
fine = r.code == ErrorCode.OK and r.ok and code in (ErrorCode.OK, ErrorCode.BUSY)
masked = st6 & 0x40 == 0x40 and len(r.values) == 2 and out.exit_code != 0
wide = code < 0x100 and counts == (1, 2) and (r.code, k) == (ErrorCode.OK, 2)
code(ctx, r, ErrorCode.RANGE, "out of range")


def position() -> tuple[int, int]:
    return 0, 0


def outer() -> ErrorCode:
    def inner() -> int:
        return 3
    return ErrorCode.UNKNOWN
'''


def test_the_scan_finds_planted_bare_codes():
    lines = [line for line, _ in bare_codes(PLANTED)]
    assert lines == [1, 2, 4, 5, 6, 7, 12, 17]
