"""The pytest plugin runs cases as items only when asked, and as pytest users expect:
collected as a tree (target > section > case) that --collect-only counts; nothing else
collected beside them; NON-STRICT and INFO as outcomes of their own in the summary and
under -rA; skips that name the case and why; markers per tag and need; JUnit with the
suite's classname and the verdict visible."""

from __future__ import annotations

import re
import shlex
import sys
import xml.etree.ElementTree as ET
from types import SimpleNamespace

import pytest

from conformance.pytest_plugin.plugin import pytest_report_teststatus
from conformance.reports.junit import classname
from conformance.run.selection import select
from conformance.verdicts.verdict import INFO, NON_STRICT
from gve_fixtures.profile import available_profiles

pytest_plugins = ["pytester"]

#: a reading that takes `+5` for 5: two cases of section 3 grade it NON-STRICT
LENIENT = "emu:GVE84-100?reading=plus-sign"


def test_cases_become_items_and_nothing_else_is_collected(pytester):
    pytester.makepyfile("def test_nothing():\n    assert True\n")
    result = pytester.runpytest("--gve-target", "emu:GVE84-100",
                                "--gve-cases", "5.errors.*", "-q")
    result.assert_outcomes(passed=len(select(["5.errors.*"])))
    assert "test_nothing" not in result.stdout.str()


def test_inert_without_a_target(pytester):
    pytester.makepyfile("def test_nothing():\n    assert True\n")
    result = pytester.runpytest("-q")
    result.assert_outcomes(passed=1)


def test_pyargs_conformance_runs_the_cases_on_the_default_target(pytester):
    result = pytester.runpytest("--pyargs", "conformance", "--gve-cases", "5.errors.*", "-q")
    result.assert_outcomes(passed=len(select(["5.errors.*"])))
    result.stdout.fnmatch_lines(["*passed*"])


def test_collect_only_lists_the_tree_and_counts_it(pytester):
    cases = select(["5.errors.*", "1.profile.version"])
    result = pytester.runpytest("--gve-target", "emu:GVE84-100", "--gve-cases", "5.errors.*",
                                "--gve-cases", "1.profile.version", "--collect-only")
    out = result.stdout.str()
    assert "no tests collected" not in out
    result.stdout.fnmatch_lines([f"*{len(cases)} tests collected*"])
    result.stdout.fnmatch_lines(["<GveTarget emu:GVE84-100>", "  <GveSection section1>",
                                 "    <GveItem 1.profile.version[[]emu:GVE84-100[]]>"])
    assert all(f"<GveItem {c.id}[emu:GVE84-100]>" in out for c in cases)


def test_non_strict_is_an_outcome_of_its_own_with_why(pytester):
    result = pytester.runpytest("--gve-target", LENIENT, "--gve-cases", "3.*", "-rA")
    out = result.stdout.str()
    # the last line counts them apart: "11 passed, 1 skipped, 2 non-strict in 1.2s"
    last = out.rstrip().splitlines()[-1]
    outcomes = {noun: int(n) for n, noun in re.findall(r"(\d+) ([\w-]+)", last)}
    assert outcomes.get("non-strict", 0) >= 1 and "failed" not in outcomes, last
    summary = out[out.index("gve-conformance: NON-STRICT and INFO"):]
    lines = [line for line in summary.splitlines() if line.startswith(NON_STRICT)]
    assert len(lines) == outcomes["non-strict"]
    # each names its case and the rule the deciding check judges, a [D] rule
    assert any("3.params.decimal [D]" in line for line in lines), lines
    assert not any(line.startswith("PASSED") and "3.frame.syntax-errors" in line
                   for line in out.splitlines())


def test_info_and_non_strict_have_their_own_letter_and_word():
    for verdict, letter in ((NON_STRICT, "N"), (INFO, "I")):
        report = SimpleNamespace(when="call", gve_verdict=verdict)
        category, short, word = pytest_report_teststatus(report, None)
        assert (short, word) == (letter, verdict) and category == verdict.lower()
    assert pytest_report_teststatus(SimpleNamespace(when="call"), None) is None


def test_a_skip_names_the_case_and_why(pytester):
    # the GVE54 lacks EFW: the float-values case is MISSING there
    result = pytester.runpytest("--gve-target", "emu:GVE54", "--gve-cases", "3.params.*",
                                "-rs")
    out = result.stdout.str()
    skips = [line for line in out.splitlines() if line.startswith("SKIPPED")]
    assert skips and all("plugin.py" not in line for line in skips), skips
    assert any("MISSING 3.params.float-values [emu:GVE54]: " in line
               and "the profile lacks" in line for line in skips), skips


def test_markers_choose_by_need_and_tag(pytester):
    everything = select(["10.6.*"])
    wanted = [c for c in everything if not c.destructive]
    assert wanted and len(wanted) < len(everything)
    result = pytester.runpytest("--gve-target", "emu:GVE84-100", "--gve-cases", "10.6.*",
                                "-m", "not destructive", "--collect-only", "-q")
    result.stdout.fnmatch_lines([f"*{len(wanted)}/{len(everything)} tests collected "
                                 f"({len(everything) - len(wanted)} deselected)*"])
    tagged = [c for c in select(["5.*"]) if c.tag == "M"]
    result = pytester.runpytest("--gve-target", "emu:GVE84-100", "--gve-cases", "5.*",
                                "-m", "tag_M", "--collect-only", "-q")
    result.stdout.fnmatch_lines([f"*{len(tagged)}/{len(select(['5.*']))} tests collected*"])


def test_junit_gives_the_suite_s_classname_and_the_verdict(pytester):
    xml = pytester.path / "junit.xml"
    pytester.runpytest("--gve-target", LENIENT, "--gve-cases", "3.*", f"--junitxml={xml}")
    cases = {c.get("name"): c for c in ET.parse(xml).getroot().iter("testcase")}
    case = cases[f"3.frame.syntax-errors[{LENIENT}]"]
    section = select(["3.frame.syntax-errors"])[0].section
    assert case.get("classname") == classname("GVE84-100", section)
    props = {p.get("name"): p.get("value") for p in case.iter("property")}
    assert props["verdict"] == NON_STRICT
    (skipped,) = case.findall("skipped")
    assert skipped.get("message").startswith(f"{NON_STRICT} 3.frame.syntax-errors")


def test_a_known_state_step_the_unit_breaks_fails_the_pytest_run(pytester):
    target = "exec:" + shlex.join([sys.executable, "-m", "emulator", "--cosim", "--model",
                                   "GVE84-100", "--mutant", "delete-ignored"])
    result = pytester.runpytest("--gve-target", target, "--gve-profile", "GVE84-100",
                                "--gve-cases", "5.errors.ok", "-q")
    assert result.ret == pytest.ExitCode.TESTS_FAILED
    result.stdout.fnmatch_lines(["*FAIL on exec:*10.4.delete: the known state: D after H*"])


def test_the_plugin_mirrors_the_command_line_s_options(pytester):
    """--gve-mutant plants a bug, --gve-exclude leaves cases out, emu:all is every profile,
    and -rA's FAIL lines carry why, whole."""
    result = pytester.runpytest("--gve-target", "emu:GVE84-100", "--gve-mutant",
                                "range-error-code", "--gve-cases", "5.errors.*",
                                "--gve-exclude", "5.errors.busy", "-rA")
    kept = select(["5.errors.*"], ["5.errors.busy"])
    result.assert_outcomes(passed=len(kept) - 1, failed=1)
    result.stdout.fnmatch_lines([
        "gve-conformance: FAILED — 1 FAIL,*",
        "*short test summary info*",
        'FAILED */section5::5.errors.out-of-range[[]emu:GVE84-100[]] - FAIL: 5.code.range '
        '[[]M-ex[]] SW8,F1 → 5: observed "code 4", expected "code 5"'])
    # pytest's own lines carry why: they are not listed again
    assert "gve-conformance: FAIL and ERROR" not in result.stdout.str()
    every = pytester.runpytest("--gve-target", "emu:all", "--gve-cases", "1.profile.version",
                               "-q")
    every.assert_outcomes(passed=len(available_profiles()))


def test_every_plugin_option_has_its_help(pytester):
    helped = pytester.runpytest("--help").stdout.str()
    for option in ("--gve-yes", "--gve-max-travel", "--gve-allow-destructive", "--gve-mutant",
                   "--gve-exclude", "--gve-seed", "--gve-accept-incomplete"):
        # the option, its metavar, then words of help (not straight the next option)
        assert re.search(rf"\n\s+{option}(?:[ =][A-Z_|:/]+)?\s+(?!-)\w", helped), option
    assert "the Hypothesis machines' seed" in helped and "plant this deliberate bug" in helped
