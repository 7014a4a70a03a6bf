"""The suite's power: it FAILs every deliberately broken emulator (naming the case that
caught it); that it PASSes the clean one on every profile is asserted of the default run,
which is that run (tests/conformance/cli/test_run.py). The hunt is the one of
`gve-conformance mutation`: a mutant is stopped at the first case that FAILs it and
PASSes the clean emulator, cases of its rule area first."""

from __future__ import annotations

import re

import pytest

from conformance.cli import mutation
from conformance.cli.mutation import Hunt, hunt, main
from conformance.run.runner import run
from conformance.run.selection import select
from conformance.targets import emu, parse_target
from conformance.verdicts.verdict import ERROR
from gve_fixtures.profile import load_profile

MUTANTS = emu.mutants()


# the mutation gate (`gve-conformance mutation --sweep`, a step of .ci/run) runs this very
# hunt for every mutant and fails on a mutant missed or an ERROR met: slow, as the other
# tests the gates repeat
@pytest.mark.slow
@pytest.mark.parametrize("mutant", sorted(MUTANTS))
def test_the_suite_fails_every_mutant(mutant: str) -> None:
    h = hunt(mutant)
    assert h.caught, f"no case caught the mutant {mutant} ({h.description})"
    assert not h.errors, f"suite defects met while hunting {mutant}: {h.errors}"
    print(f"{mutant} caught by {h.caught_by} in {h.seconds:.2f} s")


def test_the_command_prints_the_score(capsys) -> None:
    mutant = "go-without-inta"          # one every family shows (some show on one only)
    assert main(["--mutant", mutant, "--profile", "GVE84-100"]) == 0
    out = capsys.readouterr().out
    assert f"caught  {mutant}" in out and "mutation score: 1/1 = 100.0 %" in out


def test_a_mutant_no_case_checks_is_missed_and_the_score_says_so(capsys) -> None:
    # only the firmware-string case: it cannot see a broken watchdog
    assert main(["--mutant", "watchdog-never", "--cases", "1.profile.version"]) == 1
    out = capsys.readouterr().out
    assert "MISSED  watchdog-never" in out and "0/1 = 0.0 %" in out


@pytest.mark.parametrize("argv", [["--mutant", "no-such-bug"], ["--profile", "GVE99"],
                                  ["--jobs", "0"]])
def test_bad_arguments_are_one_line_and_exit_2(argv, capsys) -> None:
    assert main(argv) == 2
    assert len(capsys.readouterr().err.strip().splitlines()) == 1


def test_an_error_on_the_way_fails_the_command(capsys, monkeypatch) -> None:
    # a broken unit must make a case FAIL, never crash it: the score alone would hide that
    mutant = "go-without-inta"          # one every family shows (some show on one only)

    def crashed(name, *args):
        h = Hunt(name, "6", "")
        h.caught_by, h.runs, h.errors = "6.x [GVE84-100]", 2, ["6.y [GVE84-100]"]
        return h

    monkeypatch.setattr(mutation, "hunt", crashed)
    assert main(["--mutant", mutant]) == 1
    out = capsys.readouterr().out
    assert "ERROR on the way (a defect of the suite): 6.y [GVE84-100]" in out
    assert "1/1 = 100.0 %" in out and "1 ERROR" in out


def test_the_sweep_runs_the_catalogue_past_the_catch(capsys) -> None:
    argv = ["--mutant", "go-without-inta", "--profile", "GVE84-100", "--cases", "5.errors.*"]
    assert main(argv) == 0
    hunted = capsys.readouterr().out
    assert main([*argv, "--sweep"]) == 0
    swept = capsys.readouterr().out
    runs = [int(re.search(r"; (\d+) case runs", text).group(1)) for text in (hunted, swept)]
    # the sweep runs what the hunt left, but only where the clean run reached the mutant
    unreached = int(re.search(r"; (\d+) not run, the mutant's code unreached", swept).group(1))
    assert runs[0] < runs[1] + unreached == len(
        [c for c in select(["5.errors.*"]) if not c.missing_for(load_profile("GVE84-100"))])
    assert "0 ERROR" in swept


@pytest.mark.slow
@pytest.mark.parametrize("mutant", sorted(MUTANTS))
def test_every_check_a_mutant_meets_names_its_rule(mutant: str) -> None:
    # the whole catalogue, not only up to the catch: a broken unit takes the paths where
    # a check is recorded only on failure (a check naming no rule is an ERROR)
    for profile in mutation.FIRST:
        result = run([parse_target(f"emu:{profile}?mutant={mutant}")], select(),
                     settings_name="mutation")
        unnamed = [f"{r.id}: {c['what']}" for r in result.results for c in r.checks
                   if not c["rule"]]
        errors = [f"{r.id}: {r.notes[-1][-200:]}" for r in result.results
                  if r.verdict == ERROR]
        assert unnamed == [] and errors == [], profile
