"""Build hooks that pyproject.toml cannot express: the package list (with `fixtures/`
installed as `gve_fixtures`) and the optional C stepper built through cffi."""

from setuptools import find_packages, setup

packages = [*find_packages(include=["emulator*", "conformance*"]), "gve_fixtures"]

setup(packages=packages)
