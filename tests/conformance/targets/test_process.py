"""exec: targets end to end, in real time: the emulator started as a program stands for a
clone's simulator. Its control channel is the rig (rig cases PASS, a rig-area mutant
FAILs its case); without one the rig cases are COULD-NOT-TEST; the program is stopped
at the end, also after Ctrl-C, and one that dies mid-run ends the run for its target at
once with the target's failure; bad specs are one line and exit status 2."""

from __future__ import annotations

import itertools
import json
import os
import shlex
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from conformance.case.context import Case
from conformance.cli import main as program
from conformance.cli.run import main
from conformance.run.runner import run
from conformance.run.selection import select
from conformance.targets import TargetError, parse_target, process
from conformance.verdicts.verdict import COULD_NOT_TEST, ERROR, FAIL, PASS
from gve_fixtures.transcript import HOST, load
from tests.processes import stop

pytestmark = pytest.mark.pty
pytest_plugins = ["pytester"]

EMULATOR = [sys.executable, "-m", "emulator"]
#: a simulator that dies at a frame of its choosing (its docstring)
DYING = [sys.executable, str(Path(__file__).with_name("dying_relay.py"))]
#: rig cases that use every command of the channel: in, switch, power-on, state
RIG_CASES = ["10.cmd.output.port", "10.cmd.reference.to-switch",
             "10.3.inputs.level-after-clearing", "10.3.inputs.physical-across-restart"]


def exec_target(command: list[str], **options):
    target = parse_target("exec:" + shlex.join(command), profile="GVE84-100",
                          allow_destructive=True, **options)
    target.preflight()
    return target


def gone(pid: int) -> bool:
    """No process ``pid`` runs (none at all, or a zombie some other parent has not reaped
    yet: never one of ours, which the target reaps)."""
    try:
        with open(f"/proc/{pid}/stat") as stat:
            return stat.read().rsplit(")", 1)[1].split()[0] in "ZX"
    except FileNotFoundError:
        return True


def verdicts(result) -> dict[str, str]:
    return {r.id: r.verdict for r in result.results}


@pytest.mark.parametrize("where", [["--pty"], ["--tcp", "127.0.0.1:0"]])
def test_the_rig_cases_pass_on_the_emulator_as_a_program(where):
    target = exec_target([*EMULATOR, *where])
    pid = target.program.process.pid
    assert target.info.has_rig and target.info.kind == "exec"
    cases = RIG_CASES if where == ["--pty"] else RIG_CASES[:1]
    result = run([target], select(cases))
    assert verdicts(result) == {case: PASS for case in cases}, [
        (r.id, r.notes, r.failed_checks) for r in result.results]
    assert result.problems == []
    assert target.program is None and gone(pid), "the program was not stopped at the end"


def test_a_rig_area_mutant_fails_its_case():
    target = exec_target([*EMULATOR, "--pty", "--mutant", "interrupt-ignored"])
    result = run([target], select(["10.3.interrupt.polarity"]))
    assert verdicts(result) == {"10.3.interrupt.polarity": FAIL}


def test_without_a_rig_the_rig_cases_could_not_be_tested_and_the_others_run():
    # the emulator with its standard input closed reads no control channel
    command = ["sh", "-c", f"exec {shlex.join([*EMULATOR, '--pty'])} </dev/null"]
    target = exec_target(command)
    assert not target.info.has_rig
    result = run([target], select(["5.errors.ok", "10.cmd.output.port"]))
    assert verdicts(result) == {"5.errors.ok": PASS, "10.cmd.output.port": COULD_NOT_TEST}
    assert "test rig" in result.results[1].notes[0]


def test_a_program_that_dies_mid_run_ends_the_run_with_the_target_s_failure():
    target = exec_target([*EMULATOR, "--pty"])
    process_ = target.program.process

    def kill_after_the_first(result) -> None:
        if process_.poll() is None:
            process_.kill()

    start = time.monotonic()
    result = run([target], select(["5.errors.ok", "5.errors.unknown", "6.*"]),
                 on_result=kill_after_the_first)
    took = time.monotonic() - start
    got = [r.verdict for r in result.results]
    assert got[:2] == [PASS, FAIL] and set(got[2:]) == {COULD_NOT_TEST}, got
    assert ERROR not in got
    why = result.results[1].failed_checks[0]["what"]
    assert "program ended" in why and "killed by signal 9" in why, why
    assert all("program ended" in r.notes[0] for r in result.results[2:])
    assert any("restorations stopped" in p for p in result.problems)
    assert took < 10, f"{took:.1f} s"
    assert target.program is None and gone(process_.pid)


@pytest.mark.parametrize(("body", "when"), [
    *(("Z", when) for when in ("before", "mid-answer", "after")),
    # after its last answer it may die after the case: the next test kills it there
    *(("XQ", when) for when in ("before", "mid-answer"))])   # 5.errors.unknown's first, last
@pytest.mark.parametrize("stepper", ["c", "python"])
def test_a_program_that_dies_at_any_instant_of_a_case_fails_that_case(body, when, stepper):
    """Killed when a frame of the case arrives, when part of its answer was read, when
    all of it was: the case in progress FAILs with how the program ended, never ERRs."""
    target = exec_target([*DYING, body, when, "--stepper", stepper])
    pid = target.program.process.pid
    result = run([target], select(["5.errors.ok", "5.errors.unknown", "6.*"]))
    got = [r.verdict for r in result.results]
    assert ERROR not in got, [(r.id, r.notes) for r in result.results if r.verdict == ERROR]
    assert got[:2] == [PASS, FAIL] and set(got[2:]) == {COULD_NOT_TEST}, got
    why = result.results[1].failed_checks[-1]["what"]
    assert "program ended" in why and "killed by signal 9" in why, why
    assert all("program ended" in r.notes[0] for r in result.results[2:])
    assert target.program is None and gone(pid)


@pytest.mark.parametrize(("body", "nth"), [
    ("H", 2),           # the second case's known state (the first `H` is the first case's)
    ("Z", 1)])          # the second case's own first frame
@pytest.mark.parametrize("stepper", ["c", "python"])
def test_a_program_killed_as_a_frame_is_written_fails_that_case(stepper, body, nth):
    """Killed and reaped the instant a frame of the second case is on its pty, before
    the link asks for the answer (which sets the port's timeout first): once a rare ERROR
    under load (in the known state, before the case has its link), now the case's
    FAIL."""
    target = exec_target([*EMULATOR, "--pty", "--stepper", stepper])
    process_ = target.program.process
    serial_port = target._port._port             # pyserial's port under the target's
    write = serial_port.write
    seen = []

    def write_then_killed(data: bytes) -> int | None:
        n = write(data)
        if data[2:].split(b",")[0].rstrip(b"\r") == body.encode():
            seen.append(data)
            if len(seen) == nth:
                process_.kill()
                process_.wait()
        return n

    serial_port.write = write_then_killed
    result = run([target], select(["5.errors.ok", "5.errors.unknown", "6.*"]))
    got = [r.verdict for r in result.results]
    assert got[:2] == [PASS, FAIL] and set(got[2:]) == {COULD_NOT_TEST}, [
        (r.id, r.verdict, r.notes) for r in result.results]
    why = result.results[1].failed_checks[-1]["what"]
    assert "program ended" in why and "killed by signal 9" in why, why


def test_a_program_that_dies_as_its_case_ends_fails_that_case():
    """Killed once the case's last answer was judged, before the case's end (where the
    link listens for bytes still on their way): that case FAILs, the rest is not run."""
    target = exec_target([*EMULATOR, "--pty"])
    process_ = target.program.process

    def last_answer_then_killed(ctx) -> None:
        ctx.expect(ctx.link.send("?") is not None, "? answered")
        process_.kill()
        process_.wait()                         # ended, its pty hung up, before the end

    dying = Case("5.dies-at-the-end", last_answer_then_killed, "5.code.ok", "M", "test",
                 rules=("5.code.ok",))
    result = run([target], [dying, *select(["5.errors.ok"])])
    got = [r.verdict for r in result.results]
    assert got == [FAIL, COULD_NOT_TEST], [(r.id, r.notes) for r in result.results]
    checks = result.results[0].checks
    assert checks[0]["ok"] and not checks[-1]["ok"], checks
    assert "program ended" in checks[-1]["what"] and "killed by signal 9" in checks[-1]["what"]
    assert "program ended" in result.results[1].notes[0]


@pytest.mark.parametrize("stopping", [signal.SIGINT, signal.SIGTERM])
def test_the_program_is_stopped_after_ctrl_c(tmp_path, stopping):
    """Ctrl-C on the terminal (SIGINT to the suite's process group), or a CI job's
    timeout (SIGTERM), once the first case has ended: the program, in a group of its own,
    is still there for H, then D (its wire log shows them); the run reports the
    interruption; then the program has ended."""
    pidfile, log = tmp_path / "pid", tmp_path / "wire.gvt"
    simulator = (f"echo $$ > {shlex.quote(str(pidfile))}; exec "
                 + shlex.join([*EMULATOR, "--pty", "--log", str(log)]))
    suite = subprocess.Popen(
        [sys.executable, "-m", "conformance", "--target", "exec:" + shlex.join(
            ["sh", "-c", simulator]), "--profile", "GVE84-100", "--yes",
         "--report-dir", str(tmp_path / "reports"), "--cases", "5.errors.ok",
         "--cases", "10.2.measured.*", "-v"],     # -v: a PASS has its line in a pipe too
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, process_group=0)
    try:
        assert suite.stdout is not None
        for line in suite.stdout:
            if "5.errors.ok" in line:            # the first case has ended
                os.killpg(suite.pid, stopping)   # as a terminal's Ctrl-C, a CI's timeout
                break
        out, err = suite.communicate(timeout=60)
    finally:
        stop(suite)
    assert "Traceback" not in err, err
    assert suite.returncode == 130, out + err
    (folder,) = (tmp_path / "reports").iterdir()
    report = json.loads((folder / "results.json").read_text())
    assert report["interrupted"] is True
    pid = int(pidfile.read_text())
    assert gone(pid), "the program outlived the run"
    sent = b"".join(r.data for r in load(log).records if r.direction == HOST)
    frames = [f[2:].split(b",")[0] for f in sent.split(b"\r") if f.startswith(b"!0")]
    # the known state sends SW0..SW5 between its H and D: H then D is Ctrl-C's
    assert (b"H", b"D") in itertools.pairwise(frames), frames


@pytest.mark.parametrize(("spec", "says"), [
    ("exec:", "give the command"),
    ("exec:'unclosed", "cannot read the command"),
    ("exec:no-such-program-here --pty", "cannot start 'no-such-program-here'"),
])
def test_a_bad_exec_spec_is_one_line_and_exit_status_2(capsys, spec, says):
    assert main(["--target", spec, "--profile", "GVE84-100", "--no-reports"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and says in err, err


@pytest.mark.parametrize(("spec", "says"), [
    ("exec:false", "printed no port: false exited with status 1"),
    ("exec:sh -c 'echo bad news >&2; exit 3'", 'exited with status 3 (stderr: "bad news")'),
    ("exec:echo hello", 'first line "hello" is not a port'),
    ("exec:echo cosim ²", 'first line "cosim ²" is not a port'),
    ("exec:echo /no/such/port", "the program's port cannot be used"),
])
def test_a_program_that_serves_no_port_stops_the_run_with_one_line(capsys, spec, says):
    """The whole catalogue asked for, one line said: the target cannot start (what the
    program printed, escaped), exit status 2, no line per case."""
    assert main(["--target", spec, "--profile", "GVE84-100", "--yes", "--no-reports"]) == 2
    captured = capsys.readouterr()
    assert captured.err.count("\n") == 1, captured.err
    assert captured.err.startswith(f"gve-conformance: {spec}: ") and says in captured.err
    assert "COULD-NOT-TEST" not in captured.out and "Traceback" not in captured.out


@pytest.mark.parametrize("job", ["diff", "replay"])
def test_other_jobs_say_it_in_one_line_too(capsys, job):
    transcript = Path(__file__).parents[3] / "fixtures" / "transcripts" / \
        "g1-checksum-mode.gvt"
    argv = {"diff": ["diff", "--no-reports"], "replay": ["replay", str(transcript)]}[job]
    assert program([*argv, "--target", "exec:false", "--profile", "GVE84-100", "--yes"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "exec:false: the program printed no port" in err, err


def test_a_program_that_prints_nothing_is_given_up(monkeypatch, capsys):
    monkeypatch.setattr(process, "FIRST_LINE_SECONDS", 0.3)
    monkeypatch.setattr("conformance.targets.program.QUIT_SECONDS", 0.2)
    assert main(["--target", "exec:sleep 30", "--profile", "GVE84-100", "--cases",
                 "5.errors.ok", "--yes", "--no-reports"]) == 2
    assert "printed no port within 0.3 s" in capsys.readouterr().err


@pytest.mark.parametrize(("argv", "says"), [
    ([], "say which profile"),
    (["--profile", "auto"], "name the profile the simulator behaves as"),
    (["--profile", "GVE54", "--mutant", "sw6-inert"], "put --mutant NAME in the command"),
])
def test_exec_options_that_make_no_sense_are_one_line(capsys, argv, says):
    assert main(["--target", "exec:true", "--no-reports", *argv]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and says in err, err


def test_a_profile_that_contradicts_the_rig_s_state_is_refused():
    with pytest.raises(TargetError, match="contradicts the program, whose rig says it "
                                          "behaves as GVE54"):
        exec_target([*EMULATOR, "--pty", "--model", "GVE54"])


@pytest.mark.parametrize(("line", "url"), [
    ("/dev/pts/7", "/dev/pts/7"),
    ("socket://127.0.0.1:5114", "socket://127.0.0.1:5114"),
    ("127.0.0.1:5114", "socket://127.0.0.1:5114"),
    ("tcp 127.0.0.1:5114\r", "socket://127.0.0.1:5114"),
    ("listening on 5114", None),
    ("", None),
])
def test_the_first_line_names_the_port(line, url):
    assert process.port_url(line) == url


def test_the_plugin_runs_an_exec_target(pytester):
    result = pytester.runpytest(
        "-p", "no:cacheprovider", "--gve-target", "exec:" + shlex.join([*EMULATOR, "--pty"]),
        "--gve-profile", "GVE84-100", "--gve-yes", "--gve-cases", "10.cmd.output.port",
        "--gve-cases", "5.errors.ok", "-q")
    result.assert_outcomes(passed=2)

