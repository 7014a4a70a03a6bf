"""Every supported Python named alike in the three places that name it: the oldest that
``requires-python`` admits is the limited API the wheel is tagged for (setup.py), and
tox has a smoke environment for each version the packaging tests install the wheel on.
Fast: nothing is built (test_distributions builds and installs)."""

from __future__ import annotations

import ast
import configparser
import re
import tomllib
from pathlib import Path

from tests.packaging.test_distributions import PYTHONS

ROOT = Path(__file__).resolve().parents[2]


def _oldest() -> str:
    with (ROOT / "pyproject.toml").open("rb") as f:
        requires = tomllib.load(f)["project"]["requires-python"]
    (version,) = re.fullmatch(r">=\s*(3\.\d+)", requires).groups()
    return version


def _limited_api() -> str:
    tree = ast.parse((ROOT / "setup.py").read_text())
    (value,) = [node.value.value for node in tree.body if isinstance(node, ast.Assign)
                and [t.id for t in node.targets if isinstance(t, ast.Name)] == ["LIMITED_API"]]
    return value


def test_the_wheel_is_tagged_for_the_oldest_supported_python():
    assert _limited_api() == "cp" + _oldest().replace(".", "")
    assert PYTHONS[0] == _oldest()


def test_tox_has_a_smoke_environment_per_supported_python():
    tox = configparser.ConfigParser()
    tox.read(ROOT / "tox.ini")
    envs = [e.strip() for e in tox["tox"]["envlist"].split(",")]
    assert [e for e in envs if e.startswith("py")] == [
        "py" + v.replace(".", "") for v in PYTHONS]
    assert "{[smoke]tests}" in tox["testenv"]["commands"]
