"""`gve-conformance replay` from the command line: what it compared, then one verdict line,
the last one, that agrees with the exit status (0 PASS; 1 FAIL or COULD-NOT-TEST)."""

from __future__ import annotations

import pytest

from conformance.cli import main
from tests.emulator.process import Emulator

#: a disagreement `diff` found on the mutant that takes lower-case commands
LOWER_CASE = """# gve-transcript 1
# title: diff: Q answered differently (code)
# rules: 3.frame.upper-case
# profiles: GVE84-100
# target: emu:GVE84-100?mutant=lower-case-command
# verdict: FAIL
# target-answer: 0,25020304\\r
# reference-answer: 3\\r
> !0q\\r
< 3\\r
"""


def _replay(tmp_path, capsys, text: str, *target: str) -> tuple[int, list[str]]:
    path = tmp_path / "t.gvt"
    path.write_text(text)
    status = main(["replay", str(path), "--target", *target])
    return status, capsys.readouterr().out.splitlines()


def test_an_agreeing_replay_ends_with_pass_and_status_0(tmp_path, capsys):
    status, lines = _replay(tmp_path, capsys, LOWER_CASE, "emu:GVE84-100")
    assert status == 0
    assert lines[0].endswith("target emu:GVE84-100 against reference emu:GVE84-100 "
                             "(GVE84-100)")
    assert any("target 3\\r" in line and "reference 3\\r" in line and
               "recorded 3\\r" in line and line.endswith(" same") for line in lines)
    assert lines[-1] == ("PASSED — PASS: the target answers as the reference does (1 frame); "
                         "the "
                         "recorded 3.frame.upper-case disagreement is gone")


def test_a_disagreeing_replay_ends_with_fail_and_status_1(tmp_path, capsys):
    status, lines = _replay(tmp_path, capsys, LOWER_CASE,
                            "emu:GVE84-100?mutant=lower-case-command")
    assert status == 1
    assert lines[-1] == ("FAILED — FAIL 3.frame.upper-case: !0q\\r target 0,25020304\\r, "
                         "reference "
                         "3\\r (code): still there")
    assert sum(line.startswith(("PASS", "FAIL", "COULD-NOT-TEST")) for line in lines) == 1


def test_another_disagreement_than_the_recorded_one_says_so(tmp_path, capsys):
    text = LOWER_CASE.replace("# rules: 3.frame.upper-case", "# rules: 7.packet.count")
    status, lines = _replay(tmp_path, capsys, text, "emu:GVE84-100?mutant=lower-case-command")
    assert status == 1
    assert lines[-1].startswith("FAILED — FAIL 3.frame.upper-case: ")
    assert lines[-1].endswith("a disagreement other than the recorded 7.packet.count")


@pytest.mark.pty
def test_over_a_pty_answers_alike_in_the_band_say_why_and_a_refused_step_is_untested(
        tmp_path, capsys):
    """Real time: a position read while moving differs within the timing band (its line
    says so, so that PASS or not it follows from what is printed); a move the envelope
    refuses leaves the transcript not replayed whole: COULD-NOT-TEST, status 1."""
    text = ("# gve-transcript 1\n# profiles: GVE84-100\n> !0V1000\\r\n< 0\\r\n"
            "> !0L300,0,0\\r\n< 0\\r\n= wait 0.15\n> !0P\\r\n< 0,150,0,0\\r\n"
            "= wait 0.3\n> !0L5000,0,0\\r\n< 0\\r\n> !0P\\r\n< 0,300,0,0\\r\n")
    emu = Emulator("--model", "GVE84-100", "--pty")
    try:
        status, lines = _replay(tmp_path, capsys, text, f"serial:{emu.first}", "--profile",
                                "GVE84-100", "--yes", "--max-travel", "1000")
    finally:
        emu.stop()
    reads = [line for line in lines if line.lstrip().startswith("> !0P\\r")]
    assert len(reads) == 2
    for line in reads:
        target = line.split(" target ")[1].split()[0]
        reference = line.split(" reference ")[1].split()[0]
        assert line.endswith(" same") if target == reference else " alike: within ±" in line
    assert "  not sent (the guard): L5000,0,0: axis X could reach 0..5300" in "\n".join(lines)
    # the answer the transcript expects is the one recorded after each frame
    assert reads[1].split(" recorded ")[1].split()[0] == "0,300,0,0\\r"
    assert status == 1
    assert lines[-1].startswith("FAILED — COULD-NOT-TEST: 1 step(s) not sent (the guard)")
