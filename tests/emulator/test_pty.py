"""`python -m emulator --pty` as a separate process, driven with pyserial exactly as a
third-party program would: the golden KEEP/RESTORE scenario and packet example, the
watchdog, the control channel, and the TCP server."""

from __future__ import annotations

import json
import selectors
import subprocess
import sys
import time

import pytest
import serial

from gve_fixtures import TRANSCRIPTS_DIR
from gve_fixtures.transcript import load
from tests.emulator.replay import play

pytestmark = pytest.mark.pty


class Emulator:
    """The emulator process, its first stdout line, and its control channel."""

    def __init__(self, *args: str) -> None:
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "emulator", *args], stdin=subprocess.PIPE,
            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True, bufsize=1)
        self.first = self.readline(20.0)

    def readline(self, timeout: float) -> str:
        sel = selectors.DefaultSelector()
        sel.register(self.proc.stdout, selectors.EVENT_READ)
        assert sel.select(timeout), "the emulator printed nothing"
        return self.proc.stdout.readline().strip()

    def control(self, text: str) -> str:
        self.proc.stdin.write(text + "\n")
        self.proc.stdin.flush()
        return self.readline(10.0)

    def stop(self) -> int:
        self.proc.terminate()
        return self.proc.wait(10)


class RealRig:
    """Time passes for real; the rig's hands are the control channel."""

    def __init__(self, emu: Emulator, port: serial.Serial) -> None:
        self.emu, self.port = emu, port

    @property
    def now(self) -> int:
        return time.monotonic_ns()

    def advance(self, seconds: float) -> None:
        # wait on the port itself: anything arriving meanwhile stays readable
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            sel = selectors.DefaultSelector()
            sel.register(self.port.fileno(), selectors.EVENT_READ)
            if sel.select(deadline - time.monotonic()):
                return

    def set_input(self, port: int, value: int) -> None:
        assert self.emu.control(f"in {port} {value:02X}") == "ok"

    def outputs(self) -> int:
        return int(json.loads(self.emu.control("state"))["outputs"], 16)

    def spindle(self) -> int:
        return json.loads(self.emu.control("state"))["spindle"]

    def power_on(self) -> None:
        assert self.emu.control("power-on") == "ok"


@pytest.fixture
def pty_unit():
    emu = Emulator("--model", "GVE84-100", "--pty")
    port = serial.Serial(emu.first, 115200, timeout=5)
    yield emu, port
    port.close()
    assert emu.stop() == 0


def test_identification_and_the_golden_packet(pty_unit):
    emu, port = pty_unit
    port.write(b"!0?\r")
    assert port.read_until(b"\r") == b"0,IP84 v3 27.1.2010\r"
    assert play(port, load(TRANSCRIPTS_DIR / "g3-packet.gvt"), RealRig(emu, port)) == []


def test_golden_keep_restore_over_the_pty(pty_unit):
    emu, port = pty_unit
    rig = RealRig(emu, port)
    assert play(port, load(TRANSCRIPTS_DIR / "g6-keep-restore.gvt"), rig) == []


def test_watchdog_over_the_pty(pty_unit):
    _emu, port = pty_unit
    port.write(b"!0V1")
    start = time.monotonic()
    assert port.read_until(b"\r") == b"2\r"
    assert time.monotonic() - start >= 0.09          # the 100 ms watchdog [D timing]


def test_control_channel(pty_unit):
    emu, port = pty_unit
    state = json.loads(emu.control("state"))
    assert state["profile"] == "GVE84-100" and state["inputs"]["1"] == "FF"
    assert emu.control("in 1 FE") == "ok"
    port.write(b"!0I1\r")
    assert port.read_until(b"\r") == b"0,FE\r"
    assert emu.control("no such thing").startswith("error:")
    assert emu.control("in 9 ZZ").startswith("error:")
    assert emu.proc.poll() is None                     # still alive


def test_tcp_server():
    emu = Emulator("--model", "GVE114-500", "--tcp", "127.0.0.1:0")
    try:
        assert emu.first.startswith("tcp 127.0.0.1:")
        port = serial.serial_for_url(f"socket://{emu.first.split()[1]}", timeout=5)
        port.write(b"!0?\r!7V300\r")
        assert port.read_until(b"\r") == b"0,IP114/500 x16 16.9.2018\r"
        assert port.read_until(b"\r") == b"0\r"
        assert json.loads(emu.control("state"))["spindle"] == 300
        port.close()
    finally:
        assert emu.stop() == 0


def test_log_is_written_line_by_line(tmp_path):
    log = tmp_path / "wire.gvt"
    emu = Emulator("--model", "GVE84-100", "--pty", "--log", str(log))
    port = serial.Serial(emu.first, 115200, timeout=5)
    port.write(b"!0?\r")
    assert port.read_until(b"\r").startswith(b"0,IP84")
    emu.proc.kill()                                    # no clean shutdown: nothing flushed late
    emu.proc.wait(10)
    records = [(r.direction, r.data) for r in load(log).records]
    assert records == [(">", b"!0?\r"), ("<", b"0,IP84 v3 27.1.2010\r")]
