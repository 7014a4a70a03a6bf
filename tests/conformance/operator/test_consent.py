"""Consent before real motion, decided by one module for every entry point: a unit in
real time (serial, TCP, an exec: program serving a port) needs a yes, given up front or
at the terminal; the embedded emulator and a co-simulator in virtual time need none.
Through the CLI and the pytest plugin alike (under pytest-xdist too), a unit on a pty
(the emulator, its wire logged) sees no motion frame without consent, and runs its cases
with it; motion declined at the question ends the run INCOMPLETE, never PASSED."""

from __future__ import annotations

import contextlib
import io
import os
import pty
import re
import select
import shlex
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from conformance.cli.usage import INCOMPLETE_STATUS
from conformance.link.safety import MOTION
from conformance.operator.consent import Consent, NoConsent, moves
from conformance.operator.console import Console
from conformance.targets import parse_target
from gve_fixtures.transcript import HOST, load
from tests.processes import stop

pytestmark = pytest.mark.pty

EMULATOR = [sys.executable, "-m", "emulator", "--model", "GVE84-100"]
CASE = "10.2.measured.trapezoid"
STILL = "1.profile.version"          # judged without moving anything
NOBODY = Console(io.StringIO(), io.StringIO(), interactive=False)


def test_only_a_unit_in_real_time_needs_a_yes():
    cosim = parse_target("exec:" + shlex.join([*EMULATOR, "--cosim"]), profile="GVE84-100")
    on_pty = parse_target("exec:" + shlex.join([*EMULATOR, "--pty"]), profile="GVE84-100")
    try:
        for target in (cosim, on_pty):
            target.preflight()           # the program's first line says which it is
        assert not moves(parse_target("emu:GVE84-100")) and not moves(cosim)
        assert moves(on_pty) and moves(parse_target("serial:/dev/ttyUSB0",
                                                    profile="GVE84-100"))
        Consent(False, NOBODY).check([parse_target("emu:GVE84-100"), cosim])
        with pytest.raises(NoConsent, match="give --gve-yes"):
            Consent(False, NOBODY, flag="--gve-yes").check([cosim, on_pty])
        Consent(True, NOBODY).check([on_pty])
    finally:
        cosim.close()
        on_pty.close()


@contextlib.contextmanager
def _logged_unit(tmp_path: Path) -> Iterator[tuple[str, Path]]:
    """The emulator on a pty writing its wire log: (the pty's path, the log once the
    unit has ended)."""
    log = tmp_path / "wire.gvt"
    unit = subprocess.Popen([*EMULATOR, "--pty", "--log", str(log)], stdin=subprocess.DEVNULL,
                            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    try:
        yield unit.stdout.readline().strip(), log
    finally:
        stop(unit)


def _motion_frames(log: Path) -> list[bytes]:
    frames = [r.data for r in load(log).records if r.direction == HOST]
    return [f for f in frames if f[2:].rstrip(b"\r").decode().startswith(tuple(MOTION))]


ENTRIES = {
    "cli": lambda path, yes: [sys.executable, "-m", "conformance", "--target",
                              f"serial:{path}", "--profile", "GVE84-100", "--cases", CASE,
                              "--cases", STILL, "--no-reports"] + (["--yes"] if yes else []),
    "plugin": lambda path, yes: [sys.executable, "-m", "pytest", "-p", "no:cacheprovider",
                                 "--gve-target", f"serial:{path}", "--gve-profile",
                                 "GVE84-100", "--gve-cases", CASE, "--gve-cases", STILL, "-rA"]
    + (["--gve-yes"] if yes else []),
}
# under pytest-xdist: the controller asks (or refuses) once, its workers take its answer
ENTRIES["plugin -n 2"] = lambda path, yes: [*ENTRIES["plugin"](path, yes), "-n", "2"]
#: how each entry point refuses a run it cannot ask about: (exit status, the option)
REFUSED = {"cli": (2, "--yes"), "plugin": (pytest.ExitCode.USAGE_ERROR, "--gve-yes"),
           "plugin -n 2": (pytest.ExitCode.USAGE_ERROR, "--gve-yes")}


@pytest.mark.parametrize("entry", sorted(ENTRIES))
def test_no_motion_without_consent(entry, tmp_path):
    with _logged_unit(tmp_path) as (path, log):
        done = subprocess.run(ENTRIES[entry](path, False), stdin=subprocess.DEVNULL,
                              capture_output=True, text=True, timeout=120, cwd=tmp_path)
    status, option = REFUSED[entry]
    assert done.returncode == status, done.stdout + done.stderr
    said = [line for line in done.stderr.splitlines() if "motion needs a yes" in line]
    assert len(said) == 1 and f"give {option} on an unattended bench" in said[0], done.stderr
    assert _motion_frames(log) == []


@pytest.mark.parametrize("entry", sorted(ENTRIES))
def test_consent_up_front_runs_the_cases(entry, tmp_path):
    with _logged_unit(tmp_path) as (path, log):
        done = subprocess.run(ENTRIES[entry](path, True), stdin=subprocess.DEVNULL,
                              capture_output=True, text=True, timeout=120, cwd=tmp_path)
    assert done.returncode == 0, done.stdout + done.stderr
    last = done.stdout.rstrip().splitlines()[-1]
    assert ("2 passed" in last) if entry != "cli" else last.startswith("PASSED — 2 PASS")
    assert _motion_frames(log) != []


def on_terminal(argv: list[str], answer: bytes, cwd: Path, deadline: float = 120.0
                ) -> tuple[int, str]:
    """Run ``argv`` with a terminal as its standard input and output, answering
    ``answer`` to the first "[y/N]": (exit status, what it printed)."""
    pid, fd = pty.fork()
    if pid == 0:                                  # the child: the command on the terminal
        os.chdir(cwd)
        os.execv(argv[0], argv)
    seen, answered, end = b"", False, time.monotonic() + deadline
    try:
        while time.monotonic() < end:
            ready, _, _ = select.select([fd], [], [], 0.5)
            if not ready:
                continue
            try:
                chunk = os.read(fd, 4096)
            except OSError:                        # the child has ended: the terminal closed
                break
            if not chunk:
                break
            seen += chunk
            if not answered and b"[y/N]" in seen:
                os.write(fd, answer + b"\r")
                answered = True
    finally:
        os.close(fd)
    _, status = os.waitpid(pid, 0)
    # a terminal gets colour: the text without its escape sequences
    return os.waitstatus_to_exitcode(status), re.sub(r"\x1b\[[0-9;]*m", "",
                                                     seen.decode(errors="replace"))


@pytest.mark.parametrize("entry", sorted(ENTRIES))
@pytest.mark.parametrize("answer", [b"y", b"n"])
def test_the_question_on_a_terminal(entry, answer, tmp_path):
    """The same question at either entry point; only y moves the unit."""
    with _logged_unit(tmp_path) as (path, log):
        status, out = on_terminal(ENTRIES[entry](path, False), answer, tmp_path)
    assert "Move this machine? [y/N]" in out and "judged as GVE84-100" in out, out
    assert (_motion_frames(log) != []) == (answer == b"y"), out
    if answer == b"y":
        assert status == 0, out
        return
    # declined: not PASSED but INCOMPLETE, and not a passing exit status
    assert "INCOMPLETE — 1 PASS; not tested: 1 of 2 (1 motion not confirmed)" in out, out
    assert status == (INCOMPLETE_STATUS if entry == "cli" else pytest.ExitCode.TESTS_FAILED)
