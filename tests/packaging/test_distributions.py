"""Distributions that install: ``python -m build`` makes an sdist that
carries the whole tracked tree and a wheel that carries every file of the packages; each
installs into a fresh virtual environment, with the C stepper core, and passes a smoke
run; the wheel is tagged for CPython's limited API (abi3) and installs and runs on every
supported Python; docs/ci.md's job runs from the wheel (test_tox.py: ``tox`` on a fresh
clone). Slow (minutes, and pip reaches the package
index): ``.ci/run`` runs these after the default tests, ``python -m pytest -m slow
tests/packaging``."""

from __future__ import annotations

import email.parser
import os
import re
import shutil
import subprocess
import sys
import tarfile
import venv
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import pytest

from tests.conformance.fleet.recipe import DOCS, run_recipe
from tests.conformance.fleet.services import free_port

pytestmark = pytest.mark.slow

ROOT = Path(__file__).resolve().parents[2]
#: a folder of the tree -> the package it installs as
PACKAGES = {"conformance": "conformance", "emulator": "emulator", "fixtures": "gve_fixtures",
            "gve_host": "gve_host"}
SMOKE = ["gve-conformance", "--target", "emu:GVE84-100", "--cases", "6.*"]
#: every Python ``requires-python`` admits (tox.ini's envlist names the same ones)
PYTHONS = ("3.11", "3.12", "3.13")
#: exits 0 only where the compiled C stepper core loads
C_CORE = ("import sys; from emulator.motion.factory import c_available; "
          "sys.exit(not c_available())")


def run(argv: list[str], cwd: Path, timeout: float = 900) -> subprocess.CompletedProcess:
    done = subprocess.run(argv, cwd=cwd, capture_output=True, text=True, timeout=timeout,
                          check=False)
    assert done.returncode == 0, f"{argv}:\n{done.stdout[-3000:]}\n{done.stderr[-3000:]}"
    return done


def tracked() -> list[str]:
    if not (ROOT / ".git").exists() or shutil.which("git") is None:
        pytest.skip("not a git checkout: the tracked files are unknown")
    return run(["git", "ls-files"], ROOT).stdout.split()


@pytest.fixture(scope="module")
def dists(tmp_path_factory) -> dict[str, Path]:
    out = tmp_path_factory.mktemp("dist")
    # an isolated build: pip fills its environment from the package index. Without
    # PYTHONDONTWRITEBYTECODE, which makes setuptools warn that it cannot byte-compile.
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    done = subprocess.run([sys.executable, "-m", "build", "--outdir", str(out), str(ROOT)],
                          cwd=ROOT, capture_output=True, text=True, timeout=900, env=env,
                          check=False)
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    (sdist,) = out.glob("*.tar.gz")
    (wheel,) = out.glob("*.whl")
    return {"sdist": sdist, "wheel": wheel, "log": done.stdout + done.stderr}


@pytest.fixture(scope="module")
def checkout(dists, tmp_path_factory) -> Path:
    """A folder ``gve-conformance`` holding the suite's source, as a user's clone does
    (the sdist unpacked: the tracked tree)."""
    top = tmp_path_factory.mktemp("user")
    with tarfile.open(dists["sdist"]) as sdist:
        sdist.extractall(top, filter="data")
    (unpacked,) = [p for p in top.iterdir() if p.is_dir()]
    unpacked.rename(top / "gve-conformance")
    return top


def test_the_build_prints_no_warning(dists):
    warnings = [line for line in dists["log"].splitlines() if "warning" in line.lower()]
    assert not warnings, warnings


def fresh_env(folder: Path) -> Path:
    """A new virtual environment (its bin folder): nothing of this one's packages."""
    venv.create(folder, with_pip=True)
    return folder / "bin"


def test_the_sdist_carries_the_tracked_tree(dists):
    with tarfile.open(dists["sdist"]) as sdist:
        names = {name.split("/", 1)[1] for name in sdist.getnames() if "/" in name}
    missing = sorted(set(tracked()) - names)
    assert not missing, missing
    assert not [n for n in names if n.endswith((".so", ".pyc", ".o"))]


def test_the_wheel_carries_every_file_of_the_packages(dists):
    with zipfile.ZipFile(dists["wheel"]) as wheel:
        names = set(wheel.namelist())
    expected = {PACKAGES[path.split("/", 1)[0]] + "/" + path.split("/", 1)[1]
                for path in tracked() if path.split("/", 1)[0] in PACKAGES}
    assert not sorted(expected - names)
    # the C stepper core, compiled
    assert [n for n in names if n.startswith("emulator/motion/_stepper_c")]


def test_the_wheel_is_tagged_for_the_limited_api(dists):
    """One wheel for every CPython from 3.11 on: its name's tags and its WHEEL file say
    cp311-abi3, and its one extension module is a limited-API (.abi3) build."""
    name = dists["wheel"].name
    python, abi, platform = name.removesuffix(".whl").split("-")[-3:]
    assert (python, abi) == ("cp311", "abi3"), name
    with zipfile.ZipFile(dists["wheel"]) as wheel:
        names = wheel.namelist()
        (meta,) = [n for n in names if n.endswith(".dist-info/WHEEL")]
        tags = email.parser.Parser().parsestr(wheel.read(meta).decode()).get_all("Tag")
    assert tags == [f"cp311-abi3-{platform}"]
    (core,) = [n for n in names if n.startswith("emulator/motion/_stepper_c")]
    assert re.fullmatch(r"emulator/motion/_stepper_c\.abi3\.so", core), core


def _interpreter(version: str) -> str:
    """The first ``python3.N`` on PATH that runs (a pyenv shim of a version pyenv has not
    selected does not): .ci/run puts pyenv's versions on PATH when it finds them."""
    for folder in os.environ.get("PATH", "").split(os.pathsep):
        found = shutil.which(f"python{version}", path=folder)
        if found and subprocess.run([found, "-c", ""], capture_output=True,
                                    check=False).returncode == 0:
            return found
    raise AssertionError(f"no python{version} on PATH runs: every supported Python is "
                         "tested (.ci/run adds pyenv's versions to PATH)")


@pytest.mark.parametrize("version", PYTHONS)
def test_the_wheel_installs_and_runs_on_every_supported_python(dists, tmp_path, version):
    python = _interpreter(version)
    run([python, "-m", "venv", str(tmp_path / "env")], tmp_path)
    bin_dir = tmp_path / "env" / "bin"
    run([str(bin_dir / "python"), "-m", "pip", "install", "-q", str(dists["wheel"])], tmp_path)
    run([str(bin_dir / "python"), "-c", C_CORE], tmp_path)
    assert "PASSED" in run([str(bin_dir / SMOKE[0]), *SMOKE[1:]], tmp_path).stdout


def test_the_sdist_installs_builds_the_c_core_and_runs(dists, tmp_path):
    bin_dir = fresh_env(tmp_path / "env")
    run([str(bin_dir / "python"), "-m", "pip", "install", "-q", str(dists["sdist"])], tmp_path)
    run([str(bin_dir / "python"), "-c", C_CORE], tmp_path)
    done = run([str(bin_dir / SMOKE[0]), *SMOKE[1:]], tmp_path)
    assert "PASSED" in done.stdout


def test_the_ci_job_installs_the_wheel_runs_and_fails_a_broken_clone(dists, tmp_path):
    """docs/ci.md's whole shell job with the wheel as the suite and the installed
    emulator, with a planted bug, as the clone's simulator: the job fails, the reports
    are published, and the wheel's own smoke run passes."""
    port = free_port()
    env = {"GVE_SUITE": str(dists["wheel"]), "GVE_PROFILE": "GVE84-100", "GVE_PORT": str(port),
           "GVE_SIMULATOR": f"python -m emulator --mutant go-without-inta "
                            f"--tcp 127.0.0.1:{port}",
           "GVE_ARGS": "--cases 5.errors.*"}
    done = run_recipe(["settings", "install", "run-tcp", "publish"], tmp_path, env,
                      timeout=900)
    assert done.returncode == 1, done.stdout[-3000:] + done.stderr[-3000:]
    junit = ET.parse(tmp_path / "artifacts" / "junit.xml").getroot()
    assert junit.findall(".//testcase/failure")
    assert (tmp_path / "artifacts" / "gve-report" / "report.html").is_file()
    bin_dir = tmp_path / ".gve-venv" / "bin"
    run([str(bin_dir / "python"), "-c", C_CORE], tmp_path)
    assert "PASSED" in run([str(bin_dir / SMOKE[0]), *SMOKE[1:]], tmp_path).stdout


def test_the_ci_job_installs_its_default_suite_from_a_checkout(checkout):
    """docs/ci.md's settings and install blocks as written, GVE_SUITE left at its
    default: the checkout in ./gve-conformance installs and runs."""
    assert "GVE_SUITE" not in os.environ
    done = run_recipe(["settings", "install"], checkout, {}, timeout=900)
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    bin_dir = checkout / ".gve-venv" / "bin"
    assert "PASSED" in run([str(bin_dir / SMOKE[0]), *SMOKE[1:]], checkout).stdout


def test_the_acceptance_install_block_installs_as_written(checkout):
    """docs/acceptance.md's install block, run where the suite's source sits in
    ./gve-conformance: the suite and its plotting extra are installed."""
    done = run_recipe(["install"], checkout, {}, timeout=900, doc=DOCS / "acceptance.md")
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    python = checkout / ".venv" / "bin" / "python"
    run([str(python), "-c", "import matplotlib, conformance, emulator"], checkout)
