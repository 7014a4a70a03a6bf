"""`python -m emulator --pty` as a separate process, driven with pyserial exactly as a
third-party program would: the golden KEEP/RESTORE scenario and packet example, the
watchdog, the control channel, the TCP server, and the error and decision transcripts
(those that wait more than 1 s are marked slow)."""

from __future__ import annotations

import json
import time

import pytest
import serial

from gve_fixtures import TRANSCRIPTS_DIR
from gve_fixtures.transcript import load
from tests.emulator.process import Emulator, RealRig
from tests.emulator.replay import TRANSCRIPTS, play, transcript_cases

pytestmark = pytest.mark.pty


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


def _waits(path) -> float:
    """The seconds a transcript waits for (restarts count 2.5 s)."""
    total = 0.0
    for rec in load(path).records:
        if rec.direction == "=" and rec.action[0] in ("wait", "silence"):
            total += float(rec.action[1])
        elif (rec.direction == "=" and rec.action[0] == "power-on") or b"!0J" in rec.data:
            total += 2.5
    return total


def _over_the_pty():
    """The transcripts of errors (e*, decisions d*) on one profile each; those that
    wait long are slow."""
    chosen: dict[str, tuple] = {}
    chosen_files = sorted([*TRANSCRIPTS.glob("e*.gvt"), *TRANSCRIPTS.glob("d*.gvt")])
    for param in transcript_cases(chosen_files):
        path, profile = param.values
        if path.stem not in chosen or profile in ("GVE84-100", "GVE114-500"):
            chosen.setdefault(path.stem, (path, profile))
            if profile == "GVE84-100":
                chosen[path.stem] = (path, profile)
    for name, (path, profile) in sorted(chosen.items()):
        marks = [pytest.mark.slow] if _waits(path) > 1 else []
        yield pytest.param(path, profile, id=f"{name}-{profile}", marks=marks)


@pytest.mark.parametrize(("path", "profile"), list(_over_the_pty()))
def test_revised_transcript_over_the_pty(path, profile, tmp_path):
    emu = Emulator("--model", profile, "--pty", "--eeprom", str(tmp_path / "eeprom.bin"))
    port = serial.Serial(emu.first, 115200, timeout=30)
    try:
        assert play(port, load(path), RealRig(emu, port)) == []
    finally:
        port.close()
        assert emu.stop() == 0
