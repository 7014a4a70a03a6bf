"""The spec's section names (sections.toml, taken from the spec's headings) and the
order of section numbers."""

from __future__ import annotations

import tomllib
from functools import cache
from importlib import resources


@cache
def _names() -> dict[str, str]:
    text = resources.files("conformance.reports").joinpath("sections.toml").read_text("utf-8")
    return dict(tomllib.loads(text)["sections"])


def section_name(section: str) -> str:
    """The heading of spec section ``section`` ("" when the spec has none)."""
    return _names().get(section, "")


def section_title(section: str) -> str:
    """``10.5 KEEP / RESTORE``: the number with its name."""
    name = section_name(section)
    return f"{section} {name}" if name else section


def section_key(section: str) -> tuple[int, ...]:
    """Sort key: 2 < 10 < 10.1 < 11."""
    return tuple(int(p) if p.isdigit() else 1 << 30 for p in section.split("."))
