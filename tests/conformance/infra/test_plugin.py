"""The pytest plugin runs cases as items only when asked."""

from __future__ import annotations

import shlex
import sys

import pytest

pytest_plugins = ["pytester"]


def test_cases_become_items(pytester):
    pytester.makepyfile("def test_nothing():\n    assert True\n")
    result = pytester.runpytest("--gve-target", "emu:GVE84-100",
                                "--gve-cases", "5.errors.*", "-q")
    result.assert_outcomes(passed=1 + 8)


def test_inert_without_a_target(pytester):
    pytester.makepyfile("def test_nothing():\n    assert True\n")
    result = pytester.runpytest("-q")
    result.assert_outcomes(passed=1)


def test_pyargs_conformance_runs_the_cases_on_the_default_target(pytester):
    result = pytester.runpytest("--pyargs", "conformance", "--gve-cases", "5.errors.*", "-q")
    result.assert_outcomes(passed=8)
    result.stdout.fnmatch_lines(["*passed*"])


def test_a_known_state_step_the_unit_breaks_fails_the_pytest_run(pytester):
    target = "exec:" + shlex.join([sys.executable, "-m", "emulator", "--cosim", "--model",
                                   "GVE84-100", "--mutant", "delete-ignored"])
    result = pytester.runpytest("--gve-target", target, "--gve-profile", "GVE84-100",
                                "--gve-cases", "5.errors.ok", "-q")
    assert result.ret == pytest.ExitCode.TESTS_FAILED
    result.stdout.fnmatch_lines(["*FAIL on exec:*10.4.delete: the known state: D after H*"])
