"""`gve-conformance diff` and `replay` from the command line: a mutant's rule with its
transcript in the reports, the replay saying whether the disagreement is still there,
the emulator against itself over a pseudo-terminal in real time, usage errors."""

import json
import re
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from conformance.cli import main
from conformance.diff.grammar import Options, probes
from conformance.diff.sides import Side
from conformance.targets.emu import emulator_readings
from conformance.verdicts.verdict import CouldNotTest
from gve_fixtures.profile import load_profile
from gve_fixtures.rules import load_rules
from tests.conformance.diff.test_engine import ON_THE_WIRE, PROFILE, in_area
from tests.emulator.process import Emulator


def test_diff_reports_the_mutant_rule_and_replay_finds_it_again(tmp_path, capsys):
    # the search alone (the probes would show it at once); seed 1 finds it within its
    # first sixty sequences
    status = main(["diff", "--target", "emu:GVE84-100?mutant=lower-case-command",
                   "--examples", "100", "--report-dir", str(tmp_path), "--seed", "1",
                   "--no-probes"])
    out = capsys.readouterr().out
    assert status == 1 and "3.frame.upper-case" in out
    (folder,) = tmp_path.iterdir()
    gvt = folder / "diff-01.gvt"
    assert "# rules: 3.frame.upper-case" in gvt.read_text()
    results = json.loads((folder / "results.json").read_text())
    r = results["results"][0]
    assert r["verdict"] == "FAIL" and r["checks"][0]["observed"] != r["checks"][0]["expected"]
    assert main(["replay", str(gvt), "--target",
                 "emu:GVE84-100?mutant=lower-case-command"]) == 1
    last = capsys.readouterr().out.splitlines()[-1]
    assert last.startswith("FAILED — FAIL 3.frame.upper-case: ") and last.endswith(": still there")
    assert main(["replay", str(gvt), "--target", "emu:GVE84-100"]) == 0
    assert capsys.readouterr().out.splitlines()[-1].startswith(
        "PASSED — PASS: the target answers as the reference does")


@pytest.mark.parametrize("argv", [
    ["diff", "--target", "emu:NOPE"],
    ["diff", "--target", "emu:GVE84-100", "--examples", "0"],
    ["diff", "--target", "emu:GVE84-100", "--against", "emu:GVE54"],
    ["diff", "--target", "emu:GVE84-100", "--against", "tcp:127.0.0.1:1"],
    ["diff"],
    ["replay", "missing.gvt", "--target", "emu:GVE84-100"],
])
def test_usage_errors_are_one_line_and_status_2(argv, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err


def test_the_emulator_agrees_with_itself_over_a_pty(tmp_path, capsys):
    emu = Emulator("--model", "GVE84-100", "--pty")
    try:
        # a small envelope: the guard refuses the longer moves, the sequences go on
        status = main(["diff", "--target", f"serial:{emu.first}", "--profile", "GVE84-100",
                       "--examples", "12", "--no-reports", "--yes", "--max-travel", "100"])
    finally:
        emu.proc.terminate()
        emu.proc.wait(10)
    out = capsys.readouterr().out
    assert status == 0, out
    assert "12 sequences" in out and "PASS 1" in out


def _probes_over_a_pty(mutant: str | None, capsys) -> tuple[int, str]:
    written = str(len(probes(load_profile("GVE84-100"), Options(destructive=True))))
    emu = Emulator("--model", "GVE84-100", "--pty", *(("--mutant", mutant) if mutant else ()))
    try:
        status = main(["diff", "--target", f"serial:{emu.first}", "--profile", "GVE84-100",
                       "--examples", written, "--no-reports", "--yes", "--allow-destructive"])
    finally:
        emu.proc.terminate()
        emu.proc.wait(10)
    return status, capsys.readouterr().out


def test_over_a_pty_the_probes_raise_nothing_against_the_emulator(capsys):
    """Every probe in real time against the correct emulator: their slow rates, waits
    and reads at rest leave no disagreement within the timing band; one a loaded machine
    makes (the emulator's process late to step, seen once and not when replayed) is not
    counted."""
    status, out = _probes_over_a_pty(None, capsys)
    assert status == 0 and "PASS 1" in out, out
    unconfirmed = [line for line in out.splitlines() if "not confirmed" in line]
    assert all(line.endswith("not counted") for line in unconfirmed), out


@pytest.mark.slow
def test_over_a_pty_a_probe_shows_a_millisecond_timing_bug(capsys):
    """The dwell T ignored (a few milliseconds between two vectors), which the search
    alone did not find in ten minutes over a pty, is shown by its probe."""
    status, out = _probes_over_a_pty("dwell-ignored", capsys)
    assert status == 1 and "FAIL        10.2.motion.dwell" in out, out


@pytest.mark.slow
@pytest.mark.parametrize("mutant", ON_THE_WIRE)
def test_every_mutant_is_named_over_exec_by_the_probes(mutant, tmp_path):
    """What a clone's author runs, against each of the emulator's mutants as a program of
    its own (`exec:`, a pty, real time): the probes alone name a rule of the mutant's
    area, with the transcript of its finding (about half a minute each)."""
    profile = PROFILE.get(mutant, "GVE84-100")
    written = len(probes(load_profile(profile), Options(destructive=True, rig=True)))
    target = f"exec:{sys.executable} -m emulator --pty --model {profile} --mutant {mutant}"
    status = main(["diff", "--target", target, "--profile", profile, "--examples",
                   str(written), "--allow-destructive", "--yes", "--report-dir", str(tmp_path)])
    (folder,) = tmp_path.iterdir()
    results = json.loads((folder / "results.json").read_text())["results"]
    # (a search that stopped, COULD-NOT-TEST, has no check)
    found = [r for r in results if r["checks"] and in_area(r["checks"][0]["rule"], mutant)]
    assert found, (mutant, [(r["verdict"], r["checks"][:1], r["notes"]) for r in results])
    # graded by the tag of the rule it breaks: a third party's [D] difference is NON-STRICT
    first = found[0]
    manual = load_rules()[first["checks"][0]["rule"]].tag.startswith("M")
    assert first["verdict"] == ("FAIL" if manual else "NON-STRICT"), first["verdict"]
    assert status == (1 if any(r["verdict"] == "FAIL" for r in results) else 0), mutant
    assert "# rules: " in Path(first["artifacts"]["transcript"]).read_text()


@pytest.mark.slow
def test_over_exec_an_emulator_taking_every_reading_gets_no_fail(capsys):
    """A clone that reads every silence of the manuals its own way (all the readings at
    once, over `exec:`, real time): the probes name each difference's rule and none
    grades FAIL (about a minute and a half)."""
    written = len(probes(load_profile("GVE84-100"), Options(destructive=True)))
    chosen = " ".join(f"--reading {name}" for name in sorted(emulator_readings()))
    target = f"exec:{sys.executable} -m emulator --pty --model GVE84-100 {chosen}"
    status = main(["diff", "--target", target, "--profile", "GVE84-100", "--examples",
                   str(written), "--allow-destructive", "--yes", "--no-reports"])
    out = capsys.readouterr().out
    findings = [line for line in out.splitlines() if line.startswith(("FAIL", "NON-STRICT",
                                                                      "INFO"))]
    assert status == 0 and findings, out
    assert not [f for f in findings if f.startswith("FAIL") or "(no known rule)" in f], out


@pytest.mark.parametrize("mutant", ["delete-refused", "delete-ignored"])
def test_a_target_whose_d_misbehaves_gets_a_fail_naming_d_and_diff_runs_on(mutant, capsys):
    """The known state between sequences does not need the D under test: its failure is
    a FAIL of D's rule (10.4), the search goes on to its budget, no traceback."""
    target = (f"exec:{sys.executable} -m emulator --cosim --model GVE84-100 "
              f"--mutant {mutant}")
    status = main(["diff", "--target", target, "--profile", "GVE84-100", "--yes",
                   "--examples", "100", "--no-reports"])
    out, err = capsys.readouterr()
    assert status == 1 and "Traceback" not in out + err
    assert "FAIL        10.4.delete: the known state: D after H" in out
    assert "100 sequences" in out


def test_a_sequence_that_leaves_a_co_simulator_unreachable_is_undone_by_its_power_on(
        tmp_path, capsys):
    """A unit that sums checksums its own way is left by `%+` where no frame framed as
    the manual states reaches it: the disagreement is kept, and the next sequence begins
    at the co-simulator's power-on (checksums off, spec 9), so the search runs its whole
    budget: never a PASS, never a traceback, no known state to fail."""
    target = (f"exec:{sys.executable} -m emulator --cosim --model GVE84-100 "
              "--mutant checksum-no-comma")
    status = main(["diff", "--target", target, "--profile", "GVE84-100", "--yes",
                   "--examples", "100", "--report-dir", str(tmp_path)])
    out, err = capsys.readouterr()
    assert status == 1 and "Traceback" not in out + err
    assert "FAIL        6.checksum.response-sum: !0%+" in out
    assert "the known state" not in out
    assert "\n100 sequences" in out
    (folder,) = tmp_path.iterdir()
    results = {r["id"]: r for r in json.loads((folder / "results.json").read_text())
               ["results"]}
    assert "diff.search.agreement" not in results


def _diff_killed_at(tmp_path: Path, first: str) -> tuple[str, Path]:
    """`diff` against a mutant, SIGKILLed (nothing of its own ending runs) right after it
    printed a line starting with ``first``: that line and the run's folder."""
    cmd = [sys.executable, "-m", "conformance", "diff", "--target",
           "emu:GVE84-100?mutant=lower-case-command", "--examples", "100000", "-v",
           "--report-dir", str(tmp_path)]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, text=True)
    try:
        line = next(line for line in proc.stdout if line.startswith(first))
    finally:
        proc.kill()
        proc.wait(30)
    assert proc.returncode == -signal.SIGKILL
    (folder,) = tmp_path.iterdir()
    return line, folder


def test_a_diff_killed_while_shrinking_keeps_what_it_saw(tmp_path):
    line, folder = _diff_killed_at(tmp_path, "seen: ")
    path = Path(line.rsplit("-> ", 1)[1].strip())
    assert "# rules: 3.frame.upper-case" in path.read_text()      # shrunk or not yet
    first = json.loads((folder / "findings.jsonl").read_text().splitlines()[0])
    assert first["event"] == "seen" and first["rule"] == "3.frame.upper-case"
    assert first["transcript"] == str(path)


def test_a_diff_killed_after_a_finding_keeps_it_in_the_reports(tmp_path):
    line, folder = _diff_killed_at(tmp_path, "FAIL ")
    assert "3.frame.upper-case" in line
    results = json.loads((folder / "results.json").read_text())["results"]
    assert [r["checks"][0]["rule"] for r in results] == ["3.frame.upper-case"]
    events = [json.loads(e)["event"] for e in
              (folder / "findings.jsonl").read_text().splitlines()]
    assert events[:2] == ["seen", "kept"]
    assert "# shrunk:" not in (folder / "diff-01.gvt").read_text()


def test_a_known_state_that_cannot_be_had_ends_in_a_verdict(tmp_path, capsys, monkeypatch):
    """A CouldNotTest from a target's known state in the middle of the search: the
    findings so far are kept, the search ends COULD-NOT-TEST, one line says why."""
    opened = [0]
    real_open = Side.open

    def open_(self, tell=(), meanwhile=None):
        opened[0] += 1
        if opened[0] > 40:
            raise CouldNotTest("the known state: D refused (7)")
        return real_open(self, tell, meanwhile)

    monkeypatch.setattr(Side, "open", open_)
    status = main(["diff", "--target", "emu:GVE84-100?mutant=lower-case-command",
                   "--examples", "500", "--report-dir", str(tmp_path)])
    captured = capsys.readouterr()
    assert status == 1 and "Traceback" not in captured.err
    assert "COULD-NOT-TEST: the known state: D refused (7)" in captured.err
    (folder,) = tmp_path.iterdir()
    verdicts = {r["id"]: r["verdict"] for r in
                json.loads((folder / "results.json").read_text())["results"]}
    assert verdicts["diff.search.agreement"] == "COULD-NOT-TEST"
    assert "FAIL" in verdicts.values()
    assert "reached: commands" in captured.out


def test_a_clean_target_whose_known_state_is_lost_never_passes(tmp_path, capsys,
                                                                monkeypatch):
    """No disagreement in the sequences that ran, then the known state lost: the search
    ended COULD-NOT-TEST, counting only the sequences that ran; no PASS, and the exit
    status is not a success's."""
    opened = [0]
    real_open = Side.open

    def open_(self, tell=(), meanwhile=None):
        opened[0] += 1
        if opened[0] > 40:
            raise CouldNotTest("the known state: a KEEP is held and J needs consent")
        return real_open(self, tell, meanwhile)

    monkeypatch.setattr(Side, "open", open_)
    status = main(["diff", "--target", "emu:GVE84-100", "--examples", "500",
                   "--report-dir", str(tmp_path)])
    captured = capsys.readouterr()
    assert status != 0 and "Traceback" not in captured.err
    last = captured.out.strip().splitlines()[-1]
    assert not last.startswith(("PASS", "PASSED")), last
    (folder,) = tmp_path.iterdir()
    (result,) = json.loads((folder / "results.json").read_text())["results"]
    assert (result["id"], result["verdict"]) == ("diff.search.agreement", "COULD-NOT-TEST")
    assert "the search stopped after" in " ".join(result["notes"])
    sequences = int(result["notes"][0].split("after ")[1].split()[0])
    assert 0 < sequences < 40, result["notes"]


def test_diff_prints_what_it_reached_beside_its_verdict(capsys):
    assert main(["diff", "--target", "emu:GVE54", "--examples", "30", "--no-reports",
                 "-v"]) == 0
    out = capsys.readouterr().out.splitlines()
    reached = next(i for i, line in enumerate(out) if line.startswith("reached: "))
    # (30 sequences end in the probes: none of the matrix's cells has run)
    assert re.fullmatch(r"reached: commands \d+/\d+, table values \d+/\d+, states \d+/\d+, "
                        r"matrix cells 0/\d+ \(\d+ %\)", out[reached])
    assert out[reached + 1].startswith("  not reached: ")
    assert out[-1].startswith("PASSED")


def test_a_search_whose_sequences_send_nothing_is_never_a_pass(capsys, monkeypatch):
    """Every sequence's start refused: no sequence is counted, the search ends
    COULD-NOT-TEST with one line, and the run is no PASS."""
    from conformance.diff.engine import Pair

    def refused(self, out):
        out.refused.append("the known state: refused for the test")
        return False

    monkeypatch.setattr(Pair, "_begin", refused)
    status = main(["diff", "--target", "emu:GVE84-100", "--examples", "50", "--no-reports"])
    captured = capsys.readouterr()
    assert status != 0 and "Traceback" not in captured.err
    assert "COULD-NOT-TEST: 20 sequences in a row sent no frame" in captured.err
    counted, last = captured.out.splitlines()[-2:]
    assert counted.startswith("0 sequences, 0 frames") and "PASS" not in counted, counted
    assert last.startswith("FAILED — no case could judge the target"), last


def test_a_search_whose_time_is_up_before_any_sequence_is_never_a_pass(capsys):
    status = main(["diff", "--target", "emu:GVE84-100", "--seconds", "0.0001",
                   "--no-reports"])
    counted, last = capsys.readouterr().out.splitlines()[-2:]
    assert status != 0
    assert counted.startswith("0 sequences, 0 frames") and "PASS" not in counted, counted
    assert "PASS" not in last, last
