"""The case catalogue: every registered case, in spec order, selected by ID globs.

Importing this module imports ``conformance.cases`` (which registers the cases); the
registry itself (``conformance.case.context``) imports no case module, so data flows one way.
"""

from __future__ import annotations

import fnmatch

import conformance.cases  # noqa: F401  (registers the catalogue)
from conformance.case.context import REGISTRY, Case


def select(include: list[str] | None = None, exclude: list[str] | None = None) -> list[Case]:
    """The cases whose ID matches one of ``include`` (all when empty) and none of
    ``exclude``, in spec-section order."""
    cases = sorted(REGISTRY.values(), key=lambda c: _order(c.id))
    if include:
        cases = [c for c in cases if any(fnmatch.fnmatch(c.id, g) for g in include)]
    if exclude:
        cases = [c for c in cases if not any(fnmatch.fnmatch(c.id, g) for g in exclude)]
    return cases


def _order(id: str) -> tuple:
    return (*tuple(int(p) if p.isdigit() else 1000000 for p in id.split(".")[:3]), id)
