"""`python -m emulator` refuses what it cannot serve with one line on stderr and exit
status 2, before it serves anything, never with a traceback."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from gve_fixtures.profile import load_profile
from tests.emulator.process import Emulator


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


def _fifo(place: Path) -> Path:
    os.mkfifo(place / "fifo")                 # opened for reading, it would wait forever
    return place / "fifo"


def _sized(size: int):
    def make(place: Path) -> Path:
        (place / f"{size}.eeprom").write_bytes(bytes(size))
        return place / f"{size}.eeprom"
    return make


#: what --eeprom may not be, and what the refusal says it is
NO_IMAGES = {
    "a FIFO": (_fifo, "a FIFO, not an image file"),
    "a device": (lambda _: Path("/dev/zero"), "a device, not an image file"),
    "a directory": (lambda place: place, "a directory, not an image file"),
    **{f"{size} bytes": (_sized(size), f"{size} bytes, an image is 256")
       for size in (0, 10, 300, 10 * 1024 * 1024)},
}


@pytest.mark.parametrize("what", list(NO_IMAGES))
def test_an_eeprom_file_that_is_no_image_is_refused_before_the_port(tmp_path: Path,
                                                                     what: str) -> None:
    make, says = NO_IMAGES[what]
    image = make(tmp_path)
    size = image.stat().st_size if image.is_file() else None
    done = run("--pty", "--eeprom", str(image))          # bounded: run's timeout
    assert done.returncode == 2 and done.stdout == ""
    lines = done.stderr.splitlines()
    assert len(lines) == 1 and lines[0] == (f"gve-emulator: cannot keep the EEPROM image "
                                            f"in {image}: {says}"), lines
    if size is not None:
        assert image.stat().st_size == size               # left as it was


def test_an_absent_eeprom_image_is_created_and_an_image_is_taken(tmp_path: Path) -> None:
    image = tmp_path / "unit.eeprom"
    for _ in range(2):                                    # absent, then the image made
        emu = Emulator("--model", "GVE84-100", "--pty", "--eeprom", str(image))
        try:
            assert emu.first.startswith("/dev/") and "time_ns" in emu.state()   # serving
            assert image.read_bytes() == load_profile("GVE84-100").eeprom.image()
        finally:
            assert emu.stop() == 0


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


class _Log:
    closed = False

    def close(self) -> None:
        self.closed = True


@pytest.mark.parametrize("gone", [True, False])
def test_serving_ends_quietly_when_stdout_goes_and_closes_the_transcript(monkeypatch, gone):
    import types

    import emulator.__main__ as program
    from emulator.link.server import StdoutGone

    silenced: list[bool] = []
    monkeypatch.setattr(program, "silence_stdout", lambda: silenced.append(True))
    line = types.SimpleNamespace(log=_Log())
    with program._ending_quietly(line):
        if gone:
            raise StdoutGone
    assert silenced == ([True] if gone else []) and line.log.closed
    with pytest.raises(KeyboardInterrupt), program._ending_quietly(line):
        raise KeyboardInterrupt             # anything else is not swallowed
