"""Every bad input through every subcommand: one line on standard error, exit status 2,
and nothing sent — the unit behind the sentinel proxy never sees a frame, and a host
program is never started."""

from __future__ import annotations

import os

import pytest

from conformance.cli import main
from tests.conformance.safety.proxy import unit_behind_proxy


@pytest.fixture(scope="module")
def sentinel():
    """A unit behind a recording proxy; every test leaves it without a frame."""
    with unit_behind_proxy("--model", "GVE84-100") as (_, proxy):
        yield proxy
        assert proxy.sent() == []


@pytest.fixture
def blocker(tmp_path):
    """A file where a folder is wanted."""
    path = tmp_path / "a-file"
    path.write_text("")
    return str(path)


def _refused(argv: list[str], says: str, capsys, prog: str) -> None:
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1, err
    assert err.startswith(f"{prog}: ") and says in err, err


def _serial(proxy) -> list[str]:
    return ["--target", f"serial:{proxy.path}", "--profile", "GVE84-100", "--yes"]


RUN_MISTAKES = {
    "a run id that climbs out": (["--run-id", "../../escape"], "no '/' and no '..'"),
    "a run id with a folder": (["--run-id", "a/b"], "one folder name"),
    "a run id of dots": (["--run-id", ".."], "one folder name"),
    "a database of an unknown scheme": (["--hypothesis-db", "ftp://x/y"], "unknown scheme"),
    "a database of no name": (["--hypothesis-db", ""], "an empty name"),
    "an envelope beyond the vector range": (["--max-travel", "2147483648"],
                                            "1 to 2147483647 full steps"),
    "an envelope in scientific notation": (["--max-travel", "1e30"], "not a whole number"),
    "no jobs": (["--jobs", "0"], "give 1 or more"),
}


@pytest.mark.parametrize("mistake", sorted(RUN_MISTAKES))
def test_the_run_refuses_before_anything_is_sent(mistake, sentinel, capsys, tmp_path):
    argv, says = RUN_MISTAKES[mistake]
    _refused([*_serial(sentinel), "--report-dir", str(tmp_path), *argv], says, capsys,
             "gve-conformance")
    assert not (tmp_path.parent / "escape").exists()


DIFF_MISTAKES = {
    "seconds that are not a number": (["--seconds", "nan"], "above 0"),
    "endless seconds": (["--seconds", "inf"], "above 0"),
    "negative seconds": (["--seconds", "-1"], "above 0"),
    "no examples": (["--examples", "0"], "give 1 or more"),
    "no envelope": (["--max-travel", "0"], "give 1 or more"),
    "an envelope beyond the vector range": (["--max-travel", "9999999999"],
                                            "1 to 2147483647"),
}


@pytest.mark.parametrize("mistake", sorted(DIFF_MISTAKES))
def test_diff_refuses_before_anything_is_sent(mistake, sentinel, capsys, tmp_path):
    argv, says = DIFF_MISTAKES[mistake]
    _refused(["diff", *_serial(sentinel), "--report-dir", str(tmp_path), *argv], says,
             capsys, "gve-conformance diff")


def test_diff_refuses_a_report_dir_that_is_a_file(sentinel, capsys, blocker):
    _refused(["diff", *_serial(sentinel), "--report-dir", f"{blocker}/reports"],
             "cannot write reports to", capsys, "gve-conformance diff")


HOST_MISTAKES = {
    "a timeout that is not a number": (["--host-timeout", "nan"], "above 0"),
    "a baud rate of 0": (["--baud", "0"], "give 1 or more"),
    "a tcp port beyond 65535": (["--port", "tcp:127.0.0.1:99999"], "PORT 0..65535"),
    "a tcp host that cannot be": (["--port", "tcp:999.1.1.1:5"], "--port tcp:999.1.1.1:5"),
    "no jobs": (["--jobs", "0"], "give 1 or more"),
}


@pytest.mark.parametrize("mistake", sorted(HOST_MISTAKES))
def test_host_refuses_before_a_host_is_started(mistake, capsys, tmp_path):
    argv, says = HOST_MISTAKES[mistake]
    started = tmp_path / "started"
    _refused(["host", "--profile", "GVE84-100", "--report-dir", str(tmp_path), *argv, "--",
              "touch", str(started), "{port}"], says, capsys, "gve-conformance host")
    assert not started.exists()


def test_host_refuses_a_report_dir_that_is_a_file(capsys, tmp_path, blocker):
    started = tmp_path / "started"
    _refused(["host", "--profile", "GVE84-100", "--report-dir", f"{blocker}/r", "--",
              "touch", str(started), "{port}"], "cannot write reports to", capsys,
             "gve-conformance host")
    assert not started.exists()


HEADER = "# gve-transcript 1\n# profiles: GVE84-100\n"

TRANSCRIPTS = {
    "a wait that is not a number": (HEADER + "> !0?\\r\n= wait nan\n", "= wait nan"),
    "a wait of ages": (HEADER + "> !0?\\r\n= wait 1e308\n", "give 0 to 3600"),
    "a wait of no number": (HEADER + "= wait\n", "malformed"),
    "a fill of no frames": (HEADER + "= fill 0 !0L1,0,0\\r\n", "give 1 to"),
    "binary bytes": (b"\x00\xff\x13junk", "not a transcript (byte 0x00 at offset 0"),
    "UTF-16": (HEADER.encode("utf-16"), "it looks like UTF-16"),
    "not a transcript": ("hello\n", "first line must be"),
}


@pytest.mark.parametrize("mistake", sorted(TRANSCRIPTS))
def test_replay_refuses_a_bad_transcript(mistake, sentinel, capsys, tmp_path):
    text, says = TRANSCRIPTS[mistake]
    path = tmp_path / "t.gvt"
    path.write_bytes(text if isinstance(text, bytes) else text.encode())
    _refused(["replay", str(path), *_serial(sentinel)], says, capsys,
             "gve-conformance replay")


@pytest.mark.parametrize("what", ["/dev/zero", "a FIFO", "a folder"])
def test_replay_refuses_what_is_not_a_file_without_reading_it(what, sentinel, capsys,
                                                             tmp_path):
    path = {"/dev/zero": "/dev/zero", "a folder": str(tmp_path)}.get(what)
    if path is None:
        path = str(tmp_path / "fifo")
        os.mkfifo(path)
    _refused(["replay", path, *_serial(sentinel)], "not a regular file", capsys,
             "gve-conformance replay")


def test_replay_refuses_a_transcript_too_large(sentinel, capsys, tmp_path):
    path = tmp_path / "big.gvt"
    with path.open("wb") as f:
        f.truncate(17 * 1024 * 1024)
    _refused(["replay", str(path), *_serial(sentinel)], "larger than a transcript can be",
             capsys, "gve-conformance replay")


def test_replay_of_a_fill_without_recorded_answers_runs_to_its_end(capsys, tmp_path):
    path = tmp_path / "fill.gvt"
    path.write_text(HEADER + "> !0K\\r\n< 0\\r\n= fill 3 !0L10,0,0\\r\n> !0F\\r\n")
    status = main(["replay", str(path), "--target", "emu:GVE84-100"])
    out = capsys.readouterr()
    assert status in (0, 1) and "Traceback" not in out.err
    lines = out.out.splitlines()
    assert any(line.startswith("  = fill 3 L10,0,0: ") for line in lines)
    assert lines[-1].startswith(("PASSED — PASS: ", "FAILED — FAIL "))
    assert status == (0 if lines[-1][0] == "P" else 1)


def test_mutation_refuses_no_jobs_in_one_line(capsys):
    _refused(["mutation", "--jobs", "0"], "--jobs/-j: '0': give 1 or more", capsys,
             "gve-conformance mutation")


def test_mutation_refuses_an_unknown_option_in_one_line(capsys):
    _refused(["mutation", "--bogus"], "unrecognized arguments: --bogus", capsys,
             "gve-conformance mutation")


@pytest.mark.parametrize(("argv", "says"), [
    (["mutation", "--report-dir", "FILE"], "it is a file, not a folder"),
    (["fairness", "--seconds", "0"], "give a number of seconds above 0"),
    (["corpus", "--seconds", "nan"], "give a number of seconds above 0"),
    (["mutation", "--cases", "zz*"], "no case matches --cases 'zz*'"),
    (["fairness", "--exclude", "*"], "no case matches --exclude '*'"),
])
def test_a_gate_refuses_a_mistake_in_one_line(argv, says, tmp_path, capsys):
    (tmp_path / "FILE").write_text("")
    argv = [str(tmp_path / a) if a == "FILE" else a for a in argv]
    _refused(argv, says, capsys, f"gve-conformance {argv[0]}")
    assert list(tmp_path.iterdir()) == [tmp_path / "FILE"]      # no report folder left
