"""The layout shows the architecture: the root of ``conformance/`` keeps the entry points
only (the package, ``python -m conformance`` and the modules run with ``python -m``), at
most ten; everything else lives in the room of its job (docs/architecture.md, "The
suite's rooms")."""

from __future__ import annotations

from pathlib import Path

SUITE = Path(__file__).parents[2] / "conformance"


def _entry_point(path: Path) -> bool:
    return path.name in ("__init__.py", "__main__.py") or \
        'if __name__ == "__main__":' in path.read_text(encoding="utf-8")


def test_the_root_of_the_suite_keeps_the_entry_points_only():
    modules = sorted(SUITE.glob("*.py"))
    assert len(modules) <= 10, [m.name for m in modules]
    assert [m.name for m in modules if not _entry_point(m)] == []
    assert sorted(p.name for p in SUITE.iterdir() if p.is_file() and p.suffix != ".py") == []
