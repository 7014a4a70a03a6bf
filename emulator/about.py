"""What `--version` says about the emulator every program of the project runs: the
distribution's version, the C stepper core's state and the Python it runs on.

The state is read without loading the core for the emulator's use, so that asking
never rebuilds a stale core (the emulator rebuilds it when it loads it,
motion/rebuild.py).
"""

from __future__ import annotations

import importlib
import os
import platform
import sys
from importlib.metadata import PackageNotFoundError, version

from emulator.motion.build_stepper import MODULE
from emulator.motion.rebuild import is_fresh, module_path

DISTRIBUTION = "gve-conformance"


def distribution_version() -> str:
    try:
        return version(DISTRIBUTION)
    except PackageNotFoundError:          # run from a source tree that was never installed
        return "unknown (not installed)"


def core_state() -> str:
    """``built``, ``stale`` or ``twin``, then why, in one phrase."""
    if os.environ.get("GVE_STEPPER") == "python":
        return "twin (GVE_STEPPER=python: the pure-Python twin is used)"
    module = module_path()
    if module is None:
        return "twin (the C core is not built: the pure-Python twin is used)"
    if not is_fresh(module):
        return ("stale (built from other sources: rebuilt when the emulator loads it, the "
                "pure-Python twin if that fails)")
    try:
        importlib.import_module(MODULE)
    except ImportError as err:
        return f"twin (the C core is built but does not load: {err})"
    return "built (the C core, built from the sources beside it)"


def version_text(prog: str) -> str:
    """The lines of ``prog --version``."""
    return (f"{prog} {distribution_version()}\n"
            f"C stepper core: {core_state()}\n"
            f"Python {platform.python_version()} ({sys.implementation.name})")
