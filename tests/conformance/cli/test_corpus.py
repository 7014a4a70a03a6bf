"""`gve-conformance corpus`: every implementation of the corpus is judged as a user judges
it (the CLI, an `exec:` target, its results.json); a FAIL outside its documented
departures is unfair, a documented departure no longer FAILed is power lost; the manifest
refuses what it does not know."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from conformance.cli import main
from conformance.cli.corpus import Implementation, grade, load_manifest, run_jobs
from conformance.cli.usage import UsageError

#: the emulator as a stand-in for an implementation, with a planted bug: what it FAILs
MUTANT = "halt-without-ramp"


def unit(departures: dict[str, str], mutant: str | None = MUTANT) -> Implementation:
    planted = f" --mutant {mutant}" if mutant else ""
    return Implementation(name="stand-in", kind="unit", folder=Path("."),
                          command=f"{{python}} -m emulator --model GVE84-100 --cosim{planted}",
                          profiles=("GVE84-100",), departures=departures,
                          written_from="the emulator")


@pytest.fixture(scope="module")
def mutant_outcomes():
    """The catalogue against the emulator with the planted bug, run once, through the CLI
    as the gate runs it."""
    return run_jobs(unit({}), seed=0, timeout=600)


def failed(outcomes) -> set[str]:
    from conformance.cli.corpus import failed_rules
    return {rule for _, results, _ in outcomes if results
            for _, _, rules in failed_rules(results) for rule in rules}


def test_every_fail_a_documented_departure_is_fair(mutant_outcomes):
    rules = failed(mutant_outcomes)
    assert "10.4.halt.ramp" in rules
    t = grade(unit({r: "planted" for r in rules}), mutant_outcomes)
    assert t.fair, t.unfair + t.departures_missed


def test_a_fail_outside_the_departures_is_unfair(mutant_outcomes):
    rules = failed(mutant_outcomes) - {"10.4.halt.ramp"}
    t = grade(unit({r: "planted" for r in rules}), mutant_outcomes)
    assert not t.fair
    assert any("10.4.halt.ramp" in line and "FAIL" in line for line in t.unfair), t.unfair


def test_a_departure_no_longer_failed_is_power_lost(mutant_outcomes):
    rules = failed(mutant_outcomes)
    departures = {r: "planted" for r in rules} | {"10.6.eeprom.write": "said, never seen"}
    t = grade(unit(departures), mutant_outcomes)
    assert not t.fair and not t.unfair
    assert t.departures_missed == ["departure no longer FAILed: 10.6.eeprom.write "
                                   "(said, never seen)"]


def test_a_known_defect_of_the_suite_is_listed_open_not_unfair(mutant_outcomes):
    rules = failed(mutant_outcomes) - {"10.4.halt.ramp"}
    impl = unit({r: "planted" for r in rules})
    impl = Implementation(**{**impl.__dict__, "open": {"10.4.halt.ramp": "not mended yet"}})
    t = grade(impl, mutant_outcomes)
    assert t.fair and not t.unfair
    assert any("10.4.halt.ramp" in line and "not mended yet" in line for line in t.open)

def test_an_error_is_unfair_even_with_no_failed_check():
    # a case that crashed records no failed check: its ERROR is the suite's, never a
    # departure of the implementation
    results = {"verdict": "FAILED", "reason": "", "counts": {"PASS": 1, "ERROR": 1},
               "results": [{"id": "x.case", "profile": "GVE84-100", "verdict": "ERROR",
                            "checks": []}]}
    t = grade(unit({}), [("catalogue GVE84-100", results, "FAILED")])
    assert len(t.unfair) == 1 and t.unfair[0].startswith(
        "catalogue GVE84-100: ERROR x.case [GVE84-100]: "), t.unfair


def test_a_job_that_judged_nothing_is_unfair():
    broken = Implementation(name="broken", kind="unit", folder=Path("."),
                            command=f"{sys.executable} -c 'raise SystemExit(3)'",
                            profiles=("GVE84-100",), departures={}, written_from="")
    t = grade(broken, run_jobs(broken, seed=0, timeout=60))
    assert not t.fair
    assert t.unfair[0].startswith(("catalogue GVE84-100: no results",
                                   "catalogue GVE84-100: nothing judged")), t.unfair


def test_the_gate_end_to_end(tmp_path, capsys):
    (tmp_path / "corpus.toml").write_text(
        '[[implementation]]\nname = "clean"\nkind = "unit"\nfolder = "."\n'
        'command = "{python} -m emulator --model GVE84-100 --cosim"\n'
        'profiles = ["GVE84-100"]\nwritten-from = "the reference emulator"\n')
    status = main(["corpus", "--no-reports", "--manifest", str(tmp_path / "corpus.toml"), "-q"])
    out = capsys.readouterr().out
    assert status == 0, out
    assert out.strip().splitlines()[-1].startswith("PASSED — corpus: 1/1 implementations fair")


def test_a_manifest_key_it_does_not_know_is_refused(tmp_path):
    (tmp_path / "corpus.toml").write_text(
        '[[implementation]]\nname = "x"\nkind = "unit"\nfolder = "."\ncomand = "sim"\n'
        'profiles = ["GVE84-100"]\n')
    with pytest.raises(UsageError, match=r"unknown key.*comand"):
        load_manifest(tmp_path / "corpus.toml")


def test_an_unknown_implementation_is_one_line_and_exit_2(tmp_path, capsys):
    (tmp_path / "corpus.toml").write_text("")
    assert main(["corpus", "--no-reports", "--manifest", str(tmp_path / "corpus.toml"),
                 "--implementation", "nosuch"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "unknown implementation(s) nosuch" in err


def test_a_decided_check_beside_a_manual_one_is_not_a_fail_of_its_rule():
    from conformance.cli.corpus import failed_rules
    checks = [{"ok": False, "tag": "M", "rule": "10.cmd.axis-limits"},
              {"ok": False, "tag": "D", "rule": "10.cmd.accel-range"},
              {"ok": False, "tag": "D-info", "rule": "10.cmd.modal"},
              {"ok": True, "tag": "M", "rule": "10.cmd.vk-vn"}]
    results = {"results": [{"id": "c", "profile": "p", "verdict": "FAIL", "checks": checks},
                           {"id": "e", "profile": "p", "verdict": "ERROR", "checks": []}]}
    assert failed_rules(results) == [("c [p]", "FAIL", ["10.cmd.axis-limits"]),
                                     ("e [p]", "ERROR", ["(no rule)"])]


def test_an_implementations_options_reach_every_job_it_runs(tmp_path):
    from conformance.cli.corpus import jobs_of

    (tmp_path / "corpus.toml").write_text(
        '[[implementation]]\nname = "h"\nkind = "host"\nfolder = "."\n'
        'command = "{python} host.py {port}"\nprofiles = ["GVE54"]\n'
        'options = ["--reading", "index-hex"]\n'
        '[[implementation]]\nname = "u"\nkind = "unit"\nfolder = "."\n'
        'command = "{python} sim.py --cosim"\nprofiles = ["GVE54"]\ndiff-examples = 5\n'
        'options = ["--strict"]\n')
    host, sim = load_manifest(tmp_path / "corpus.toml")
    ((_, argv),) = jobs_of(host, tmp_path, seed=0)
    assert argv[argv.index("--") - 2:argv.index("--")] == ["--reading", "index-hex"]
    assert argv[argv.index("--") + 2:] == ["host.py", "{port}"]
    jobs = jobs_of(sim, tmp_path, seed=0)
    assert [what for what, _ in jobs] == ["catalogue GVE54", "diff GVE54"]
    assert all("--strict" in argv for _, argv in jobs)
