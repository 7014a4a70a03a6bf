"""The pytest plugin runs cases as items only when asked."""

from __future__ import annotations

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
