"""Every mistake a user makes first gets one clear line and exit status
2 before anything is sent — through the command line and through the pytest plugin (a
usage error, not an INTERNALERROR or a failed test per case)."""

from __future__ import annotations

import subprocess
import sys

import pytest

from conformance.cli import main
from tests.conformance.safety.proxy import unit_behind_proxy

pytest_plugins = ["pytester"]

#: tcp targets pyserial would open wrongly (an empty host is this machine) or refuse late
BAD_TCP = {"with an empty host": "tcp::5114", "with nothing": "tcp:",
           "without a port": "tcp:localhost", "with a port that is no number": "tcp:h:notaport",
           "with a port beyond 65535": "tcp:h:99999"}

MISTAKES = {
    "port that does not exist": (["--target", "serial:/dev/gve-nosuch", "--profile",
                                  "GVE84-100"], "cannot open"),
    "baud that is not a number": (["--target", "serial:/dev/null?baud=fast", "--profile",
                                   "GVE84-100"], "bad baud 'fast'"),
    "baud zero": (["--target", "serial:/dev/null?baud=0", "--profile", "GVE84-100"],
                  "bad baud '0'"),
    "address outside 0..7": (["--target", "serial:/dev/null?address=9", "--profile",
                              "GVE84-100"], "bad address '9'"),
    "cases that select nothing": (["--cases", "zzz*"], "no case matches --cases 'zzz*'"),
    "exclude that leaves nothing": (["--exclude", "*"], "no case matches"),
    "unknown mutant": (["--target", "emu:GVE84-100", "--mutant", "nosuch"],
                       "unknown mutant 'nosuch'"),
    "unknown mutant in the target": (["--target", "emu:GVE84-100?mutant=nosuch"],
                                     "unknown mutant 'nosuch'"),
    "unknown settings": (["--settings", "bogus"], "invalid choice: 'bogus'"),
    "profile contradicting emu": (["--target", "emu:GVE54", "--profile", "GVE84-100"],
                                  "contradicts"),
    "envelope of no steps": (["--target", "serial:/dev/null", "--profile", "GVE84-100",
                              "--max-travel", "0"], "--max-travel: '0': give 1 or more"),
    "envelope not a number": (["--max-travel", "far"], "not a whole number: 'far'"),
    # one bound on every target: the embedded emulator's, and with no target at all
    "envelope beyond the GVE54's vectors": (["--target", "emu:GVE54", "--max-travel",
                                             "70000"], "1 to 65535 full steps on the GVE54"),
    "envelope beyond a vector, no target": (["--max-travel", "70000"], "on the GVE54"),
    "unknown scheme": (["--target", "bogus:x"], "unknown target 'bogus:x'"),
    "unknown profile": (["--target", "emu:GVE99"], "GVE99"),
    "real target without a profile": (["--target", "tcp:127.0.0.1:9"], "--profile"),
    "mutant on a real target": (["--target", "serial:/dev/null", "--profile", "GVE84-100",
                                 "--mutant", "go-without-inta"], "--mutant"),
    **{f"tcp target {what}": (["--target", spec, "--profile", "GVE84-100"], "tcp:HOST:PORT")
       for what, spec in BAD_TCP.items()},
}


@pytest.mark.parametrize("mistake", sorted(MISTAKES))
def test_the_command_line_refuses_with_one_line(mistake, capsys):
    argv, says = MISTAKES[mistake]
    assert main([*argv, "--no-reports"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and says in err and err.startswith("gve-conformance: ")


def test_an_unwritable_report_dir_is_refused_before_anything_is_sent(tmp_path, capsys):
    blocker = tmp_path / "a-file"
    blocker.write_text("")
    with unit_behind_proxy("--model", "GVE84-100") as (_, proxy):
        status = main(["--target", f"serial:{proxy.path}", "--profile", "GVE84-100",
                       "--report-dir", str(blocker / "reports")])
        assert proxy.sent() == []
    assert status == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "cannot write reports to" in err


@pytest.mark.parametrize("subcommand", ["diff", "replay"])
def test_the_envelope_has_one_bound_in_every_subcommand(subcommand, capsys, tmp_path):
    transcript = tmp_path / "t.gvt"
    transcript.write_text("# gve-transcript 1\n> !0?\\r\n")
    argv = [subcommand, *([str(transcript)] if subcommand == "replay" else []),
            "--target", "emu:GVE54", "--max-travel", "70000"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "1 to 65535 full steps on the GVE54" in err, err


def test_a_closed_pipe_ends_quietly():
    proc = subprocess.run(f"{sys.executable} -m conformance --list | head -1", shell=True,
                          capture_output=True, text=True, timeout=60)
    assert proc.stdout.count("\n") == 1 and proc.stderr == ""


PLUGIN_MISTAKES = {
    "unknown scheme": (["--gve-target", "bogus:x"], "unknown target"),
    "unknown settings": (["--gve-target", "emu:GVE84-100", "--gve-settings", "bogus"],
                         "--gve-settings 'bogus'"),
    "cases that select nothing": (["--gve-target", "emu:GVE84-100", "--gve-cases", "zzz*"],
                                  "no case matches"),
    "port that does not exist": (["--gve-target", "serial:/dev/gve-nosuch", "--gve-profile",
                                  "GVE84-100"], "cannot open"),
    "profile contradicting emu": (["--gve-target", "emu:GVE54", "--gve-profile", "GVE84-100"],
                                  "contradicts"),
    "unknown mutant": (["--gve-target", "emu:GVE84-100?mutant=nosuch"], "unknown mutant"),
    "envelope of no steps": (["--gve-target", "emu:GVE84-100", "--gve-max-travel", "0"],
                             "--max-travel 0: the envelope is 1 to"),
    "envelope beyond the GVE54's vectors": (["--gve-target", "emu:GVE54",
                                             "--gve-max-travel", "70000"], "on the GVE54"),
    **{f"tcp target {what}": (["--gve-target", spec, "--gve-profile", "GVE84-100"],
                              "tcp:HOST:PORT")
       for what, spec in BAD_TCP.items()},
}


@pytest.mark.parametrize("mistake", sorted(PLUGIN_MISTAKES))
def test_the_plugin_refuses_with_a_usage_error(pytester, mistake):
    argv, says = PLUGIN_MISTAKES[mistake]
    pytester.makepyfile("def test_nothing():\n    assert True\n")
    result = pytester.runpytest(*argv)
    assert result.ret == pytest.ExitCode.USAGE_ERROR
    text = result.stdout.str() + result.stderr.str()
    assert says in text and "INTERNALERROR" not in text and "Traceback" not in text


def test_a_report_dir_that_is_a_file_says_so(tmp_path, capsys):
    blocker = tmp_path / "a-file"
    blocker.write_text("")
    assert main(["--report-dir", str(blocker), "--cases", "5.errors.ok"]) == 2
    err = capsys.readouterr().err
    assert err == f"gve-conformance: cannot write reports to {blocker}: it is a file, not a " \
        "folder\n"
