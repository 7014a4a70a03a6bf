"""Colour on the console: the verdict of each line, so that a FAIL does not look like a
PASS. Plain ANSI SGR codes rather than a library: the console colours one word a line
and tqdm already draws the bar, so a dependency (``rich``) would bring a second
terminal layer for that one word (docs/decisions.md).

``--color auto`` (the default) colours a terminal only, and never when ``NO_COLOR`` is
set to anything but the empty string (no-color.org) or ``TERM`` is ``dumb``;
``always`` and ``never`` override both, as no-color.org asks of an explicit option.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from typing import TextIO

from conformance.verdicts.verdict import (
    COULD_NOT_TEST,
    ERROR,
    FAIL,
    FAILED,
    INCOMPLETE,
    INFO,
    MISSING,
    NON_STRICT,
    PASS,
    PASSED,
)

CHOICES = ("auto", "always", "never")

#: verdict -> SGR parameters (bold red for what failed, yellow for a difference...)
STYLE = {ERROR: "1;31", FAIL: "1;31", FAILED: "1;31", NON_STRICT: "33", INFO: "36",
         COULD_NOT_TEST: "35", MISSING: "2", PASS: "32", PASSED: "1;32",
         INCOMPLETE: "1;33"}


def wanted(choice: str, stream: TextIO, environ: Mapping[str, str] | None = None) -> bool:
    """Whether lines written to ``stream`` are coloured for ``--color choice``."""
    if choice not in CHOICES:
        raise ValueError(f"--color takes {', '.join(CHOICES)}, not {choice!r}")
    if choice != "auto":
        return choice == "always"
    env = os.environ if environ is None else environ
    if env.get("NO_COLOR") or env.get("TERM") == "dumb":
        return False
    isatty = getattr(stream, "isatty", None)
    return bool(isatty and isatty())


def paint(verdict: str, text: str, on: bool) -> str:
    """``text`` in ``verdict``'s colour (unchanged when ``on`` is False or the verdict
    has none)."""
    style = STYLE.get(verdict)
    return f"\x1b[{style}m{text}\x1b[0m" if on and style else text
