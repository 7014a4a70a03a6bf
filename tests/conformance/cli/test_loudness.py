"""-q and -v where they are offered beside the run: with -q `diff` and a fleet print
only their end (what failed, where the reports are, the verdict, which the exit status
agrees with) and `replay` its verdict; -v on `diff` prints each disagreement's
transcript although the reports keep it too."""

from __future__ import annotations

from conformance.cli import main
from tests.conformance.cli.test_replay import LOWER_CASE

MUTANT = "emu:GVE84-100?mutant=lower-case-command"
DIFF = ["diff", "--target", MUTANT, "--examples", "50", "--seed", "1"]


def _verdict_only(lines: list[str]) -> str:
    assert len(lines) == 1, lines
    return lines[0]


def test_diff_quiet_prints_its_end_only(tmp_path, capsys):
    assert main([*DIFF, "-q", "--report-dir", str(tmp_path)]) == 1
    lines = capsys.readouterr().out.splitlines()
    folder = next(tmp_path.iterdir())
    assert (folder / "diff-01.gvt").is_file()                     # the reports all the same
    assert lines[-1].startswith("FAILED") and lines[-2].startswith(f"reports: {folder}/")
    # the disagreement listed once, in the recap: neither the search's header nor
    # its progress
    assert lines[0].startswith("what failed (1)") and "3.frame.upper-case [D]" in lines[2]
    assert not any(line.startswith(("diff:", "[")) for line in lines)


def test_diff_verbose_prints_the_transcripts_beside_the_reports(tmp_path, capsys):
    assert main([*DIFF, "-v", "--report-dir", str(tmp_path)]) == 1
    out = capsys.readouterr().out
    written = (next(tmp_path.iterdir()) / "diff-01.gvt").read_text().splitlines()
    assert "    " + written[0] in out.splitlines()
    assert main([*DIFF, "--report-dir", str(tmp_path)]) == 1       # by default: the path
    assert "    " + written[0] not in capsys.readouterr().out.splitlines()


def test_replay_quiet_prints_the_verdict_only(tmp_path, capsys):
    path = tmp_path / "t.gvt"
    path.write_text(LOWER_CASE)
    assert main(["replay", str(path), "--target", "emu:GVE84-100", "-q"]) == 0
    assert _verdict_only(capsys.readouterr().out.splitlines()).startswith("PASSED — PASS: ")
    assert main(["replay", str(path), "--target", MUTANT, "-v"]) == 1
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("replay ") and lines[-1].startswith("FAILED — FAIL ")


def test_a_quiet_fleet_prints_its_verdict_only(capsys):
    assert main(["--target", "emu:GVE54", "--target", "emu:GVE84-100", "--jobs", "2",
                 "--cases", "1.profile.version", "--no-reports", "-q"]) == 0
    assert _verdict_only(capsys.readouterr().out.splitlines()).startswith("PASSED")
