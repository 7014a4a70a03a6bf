"""-q and -v where they are offered beside the run: `diff`, `replay` and a fleet print
only their last line with -q (the verdict, which the exit status agrees with); -v on
`diff` prints each disagreement's transcript although the reports keep it too."""

from __future__ import annotations

from conformance.cli import main
from tests.conformance.cli.test_replay import LOWER_CASE

MUTANT = "emu:GVE84-100?mutant=lower-case-command"
DIFF = ["diff", "--target", MUTANT, "--examples", "50", "--seed", "1"]


def _verdict_only(lines: list[str]) -> str:
    assert len(lines) == 1, lines
    return lines[0]


def test_diff_quiet_prints_the_verdict_only(tmp_path, capsys):
    assert main([*DIFF, "-q", "--report-dir", str(tmp_path)]) == 1
    last = _verdict_only(capsys.readouterr().out.splitlines())
    assert last.startswith("FAILED")
    assert (next(tmp_path.iterdir()) / "diff-01.gvt").is_file()    # the reports all the same


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
    assert _verdict_only(capsys.readouterr().out.splitlines()).startswith("PASS: ")
    assert main(["replay", str(path), "--target", MUTANT, "-v"]) == 1
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("replay ") and lines[-1].startswith("FAIL ")


def test_a_quiet_fleet_prints_its_verdict_only(capsys):
    assert main(["--target", "emu:GVE54", "--target", "emu:GVE84-100", "--jobs", "2",
                 "--cases", "1.profile.version", "--no-reports", "-q"]) == 0
    assert _verdict_only(capsys.readouterr().out.splitlines()).startswith("PASSED")
