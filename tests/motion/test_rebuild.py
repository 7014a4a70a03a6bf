"""The C core is never older than its sources: a build carries their digest, a changed
source makes the module stale and it is rebuilt into what the sources now say; a stale
module that cannot be rebuilt is refused, never loaded; a module without its sources
beside it is taken as built. Each test works on a copy of the sources and of the built
module in a temporary folder."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from emulator.motion.build_stepper import HERE, SOURCES
from emulator.motion.factory import c_available
from emulator.motion.rebuild import built_digest, ensure_fresh, is_fresh, module_path

pytestmark = pytest.mark.skipif(not c_available(), reason="the C stepper core is not built "
                                "(the emulator falls back to the Python twin)")

#: loads a compiled module from a file and prints what its st_probe() returns
LOAD = """
import importlib.machinery, importlib.util, sys
name = "emulator.motion._stepper_c"
loader = importlib.machinery.ExtensionFileLoader(name, sys.argv[1])
spec = importlib.util.spec_from_loader(name, loader)
module = importlib.util.module_from_spec(spec)
loader.exec_module(module)
print(module.lib.st_probe())
"""


@pytest.fixture
def copy(tmp_path: Path) -> tuple[Path, Path]:
    """The sources and the built module, copied: (their folder, the module)."""
    for name in SOURCES:
        shutil.copy(HERE / name, tmp_path / name)
    built = module_path()
    module = tmp_path / built.name
    shutil.copy(built, module)
    return tmp_path, module


def add_probe(folder: Path) -> None:
    """A change to the sources: a new function st_probe() returning 7."""
    with open(folder / "_stepper.h", "a") as f:
        f.write("int st_probe(void);\n")
    with open(folder / "_stepper.c", "a") as f:
        f.write("\nint st_probe(void) { return 7; }\n")


def test_the_built_core_carries_its_sources_digest():
    assert is_fresh(module_path())


def test_a_fresh_module_is_left_alone(copy):
    folder, module = copy
    before = module.stat()
    ensure_fresh(module, folder)
    after = module.stat()
    assert (after.st_ino, after.st_mtime_ns) == (before.st_ino, before.st_mtime_ns)


def test_a_changed_source_is_rebuilt_into_what_it_says(copy, capsys):
    folder, module = copy
    add_probe(folder)
    assert not is_fresh(module, folder)
    ensure_fresh(module, folder)
    assert is_fresh(module, folder)
    assert "older than its sources: rebuilding it" in capsys.readouterr().err
    loaded = subprocess.run([sys.executable, "-c", LOAD, str(module)], capture_output=True,
                            text=True, timeout=60)
    assert loaded.stdout.strip() == "7", loaded.stderr


def test_a_comment_is_a_change_too(copy):
    folder, module = copy
    with open(folder / "_stepper_math.h", "a") as f:
        f.write("/* a comment */\n")
    assert not is_fresh(module, folder)


def test_a_stale_module_that_cannot_be_rebuilt_is_refused(copy, monkeypatch):
    folder, module = copy
    add_probe(folder)
    old = built_digest(module)
    monkeypatch.setenv("CC", "false")           # no working compiler
    with pytest.raises(ImportError, match="could not be rebuilt"):
        ensure_fresh(module, folder)
    assert built_digest(module) == old and not is_fresh(module, folder)
    assert sorted(p.name for p in folder.iterdir()) == sorted([*SOURCES, module.name])


def test_a_module_without_its_sources_is_taken_as_built(copy):
    folder, module = copy
    (folder / "_stepper.c").unlink()
    before = module.stat().st_mtime_ns
    ensure_fresh(module, folder)
    assert is_fresh(module, folder) and module.stat().st_mtime_ns == before


def test_processes_finding_it_stale_at_once_rebuild_it_once(copy):
    folder, module = copy
    add_probe(folder)
    code = ("import sys; from pathlib import Path; from emulator.motion.rebuild import "
            "ensure_fresh; ensure_fresh(Path(sys.argv[1]), Path(sys.argv[2]))")
    procs = [subprocess.Popen([sys.executable, "-c", code, str(module), str(folder)],
                              stderr=subprocess.PIPE, text=True) for _ in range(2)]
    errs = [p.communicate(timeout=120)[1] for p in procs]
    assert [p.returncode for p in procs] == [0, 0], errs
    assert sum("rebuilding it" in err for err in errs) == 1, errs
    assert is_fresh(module, folder)
