"""`python -m emulator` refuses what it cannot serve with one line on stderr and exit
status 2, before it serves anything, never with a traceback (issue 8 item 9)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest


def run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "emulator", *args], stdin=subprocess.DEVNULL,
                          capture_output=True, text=True, timeout=30)


@pytest.mark.parametrize(("args", "says"), [
    (["--model", "NOPE", "--pty"], "no profile named 'NOPE'"),
    (["--tcp", "127.0.0.1:notaport"], "--tcp takes HOST:PORT"),
    (["--tcp", ":99999"], "--tcp takes HOST:PORT"),
    (["--tcp", "127.0.0.1"], "--tcp takes HOST:PORT"),
    (["--address", "9", "--pty"], "an address is 0..7"),
    (["--unit", "GVE54@x", "--pty"], "an address is 0..7"),
    (["--baud", "0", "--pty"], "above 0"),
    (["--baud", "-9600", "--pty"], "above 0"),
    (["--watchdog-ms", "0", "--pty"], "above 0"),
    (["--mutant", "nosuch", "--pty"], "invalid choice"),
    (["--unit", "GVE114-500@0", "--unit", "GVE84-100@7", "--pty"], "two units answer address 7"),
    (["--model", "GVE84-100"], "one of the arguments --pty --tcp --cosim is required"),
    (["--cosim", "--pty"], "not allowed with argument"),
])
def test_usage_errors_are_one_line_and_exit_2(args: list[str], says: str) -> None:
    done = run(*args)
    assert done.returncode == 2
    assert done.stdout == ""
    lines = done.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("gve-emulator: ") and says in lines[0], lines


def test_an_eeprom_place_that_cannot_be_written_is_refused(tmp_path: Path) -> None:
    blocker = tmp_path / "a-file"
    blocker.write_bytes(b"")
    for image in (tmp_path / "missing" / "unit.eeprom", blocker / "unit.eeprom", tmp_path):
        done = run("--pty", "--eeprom", str(image))
        assert done.returncode == 2, done.stderr
        lines = done.stderr.splitlines()
        assert len(lines) == 1 and "cannot keep the EEPROM image" in lines[0], lines
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a-file"]


def test_a_port_in_use_is_refused() -> None:
    import socket
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        done = run("--tcp", f"127.0.0.1:{taken.getsockname()[1]}")
    assert done.returncode == 2
    assert len(done.stderr.splitlines()) == 1 and "Traceback" not in done.stderr


def test_piping_to_head_ends_quietly() -> None:
    done = subprocess.run(f"{sys.executable} -m emulator --pty </dev/null | head -1",
                          shell=True, capture_output=True, text=True, timeout=30)
    assert done.stdout.startswith("/dev/")
    assert done.stderr == ""
