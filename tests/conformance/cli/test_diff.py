"""`gve-conformance diff` and `replay` from the command line: a mutant's rule with its
transcript in the reports, the replay saying whether the disagreement is still there,
the emulator against itself over a pseudo-terminal in real time, usage errors."""

import json

import pytest

from conformance.cli import main
from tests.emulator.process import Emulator


def test_diff_reports_the_mutant_rule_and_replay_finds_it_again(tmp_path, capsys):
    status = main(["diff", "--target", "emu:GVE84-100?mutant=lower-case-command",
                   "--examples", "300", "--report-dir", str(tmp_path), "--seed", "1"])
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
    assert "still there" in capsys.readouterr().out
    assert main(["replay", str(gvt), "--target", "emu:GVE84-100"]) == 0
    assert "no disagreement" in capsys.readouterr().out


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
