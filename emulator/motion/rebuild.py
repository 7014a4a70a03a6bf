"""The C core is never older than its sources: a build carries the digest of the files
it was built from (build_stepper.py), and before the core is imported a module whose
digest is not that of the sources beside it is rebuilt in place, as Klipper rebuilds
its C helper. A stale module that cannot be rebuilt (no compiler, a read-only
installation) is refused with ImportError, and the emulator uses the Python twin: it
never runs C code that its sources no longer describe.

A missing module is left missing (an installation without a compiler uses the twin),
and a module whose sources are not all beside it is taken as built (there is nothing
to be stale against).
Processes that find the same stale module at once rebuild it once: the rebuild holds
a lock, and the new module replaces the old one in a single rename.
"""

from __future__ import annotations

import contextlib
import importlib.util
import os
import shutil
import sys
import tempfile
from collections.abc import Iterator
from pathlib import Path

from emulator.motion.build_stepper import HERE, MARKER, MODULE, ffibuilder, source_digest

DIGEST_LENGTH = 64


def module_path() -> Path | None:
    """The compiled module the import system would load, or None when not built."""
    try:
        spec = importlib.util.find_spec(MODULE)
    except (ImportError, ValueError):
        return None
    return Path(spec.origin) if spec and spec.origin else None


def built_digest(module: Path) -> str | None:
    """The sources' digest a compiled module carries (None: none, or not readable)."""
    try:
        data = module.read_bytes()
    except OSError:
        return None
    at = data.find(MARKER)
    if at < 0:
        return None
    return data[at + len(MARKER):at + len(MARKER) + DIGEST_LENGTH].decode("ascii", "replace")


def is_fresh(module: Path, directory: Path = HERE) -> bool:
    """Whether ``module`` was built from the sources now in ``directory`` (or those are
    not all there to say otherwise)."""
    try:
        return built_digest(module) == source_digest(directory)
    except OSError:
        return True


def ensure_fresh(module: Path | None = None, directory: Path = HERE) -> None:
    """Rebuild ``module`` (default: the installed C core) from the sources in
    ``directory`` if it was built from others; ImportError if that fails."""
    module = module or module_path()
    if module is None or is_fresh(module, directory):
        return
    with _locked(directory):
        if is_fresh(module, directory):          # rebuilt meanwhile by another process
            return
        print(f"gve emulator: the C stepper core {module.name} is older than its sources: "
              "rebuilding it", file=sys.stderr)
        try:
            _rebuild(module, directory)
        except Exception as err:  # any failure leaves the stale module, refused
            raise ImportError(f"the C stepper core {module} was built from other sources "
                              f"and could not be rebuilt ({err})") from err
    if not is_fresh(module, directory):
        raise ImportError(f"the C stepper core {module} was rebuilt but does not carry "
                          "its sources' digest")


def _rebuild(module: Path, directory: Path) -> None:
    with tempfile.TemporaryDirectory(prefix="gve-stepper-") as tmp:
        built = Path(ffibuilder(directory).compile(tmpdir=tmp, verbose=False))
        staged = module.with_name(f".{module.name}.{os.getpid()}")
        try:
            shutil.copyfile(built, staged)
            shutil.copymode(module, staged)
            os.replace(staged, module)          # a process loading it sees old or new
        finally:
            with contextlib.suppress(FileNotFoundError):
                staged.unlink()


@contextlib.contextmanager
def _locked(directory: Path) -> Iterator[None]:
    """An exclusive lock on the build script (held open read-only: no file is made)."""
    try:
        import fcntl
    except ImportError:                          # no flock here: no lock
        yield
        return
    with open(directory / "build_stepper.py", "rb") as f:
        fcntl.flock(f, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(f, fcntl.LOCK_UN)
