"""Choosing a stepper core: the C core (cffi) when it is built and loadable, else the
pure-Python twin, saying so once on stderr. ``GVE_STEPPER=c`` or ``GVE_STEPPER=python``
(or the ``stepper`` argument) forces one.
"""

from __future__ import annotations

import os
import sys

from emulator.motion.interface import Deviation, Motion
from emulator.motion.python_twin import PythonMotion

_warned = False


def _c_class() -> type:
    from emulator.motion.c_core import CMotion
    return CMotion


def c_available() -> bool:
    """Whether the C core is built and loads."""
    try:
        _c_class()
    except ImportError:
        return False
    return True


def create(axes: int, max_rate: int, *, stepper: str | None = None,
           deviations: Deviation = Deviation.NONE) -> Motion:
    """A stepper core for a unit with ``axes`` axes and the variant's ``max_rate``."""
    global _warned
    choice = stepper or os.environ.get("GVE_STEPPER") or "auto"
    if choice == "python":
        return PythonMotion(axes, max_rate, deviations)
    if choice not in ("c", "auto"):
        raise ValueError(f"unknown stepper {choice!r}: use 'c' or 'python'")
    try:
        cls = _c_class()
    except ImportError as err:
        if choice == "c":
            raise ImportError(f"the C stepper core is not available: {err}") from err
        if not _warned:
            print(f"gve emulator: C stepper core unavailable ({err}); using the Python twin",
                  file=sys.stderr)
            _warned = True
        return PythonMotion(axes, max_rate, deviations)
    return cls(axes, max_rate, deviations)
