"""The real-time server cannot be frozen or exhausted by a host or a controller (docs/decisions.md
on the real-time server; spec 3 for the frame bound). Every test runs
`python -m emulator` on loopback or a pty and is bounded by deadlines."""

from __future__ import annotations

import os
import random
import signal
import socket
import time
from pathlib import Path

import pytest
import serial

import emulator  # noqa: F401  (registers gve://)
from emulator.link.line import TimeRangeError
from tests.emulator.process import Emulator

pytestmark = pytest.mark.pty

MB = 1 << 20


def rss_kib(pid: int) -> int:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1])
    raise AssertionError("no VmRSS")


def read_answer(sock: socket.socket, timeout: float = 10.0) -> bytes:
    sock.settimeout(timeout)
    out = b""
    while not out.endswith(b"\r"):
        chunk = sock.recv(1)
        assert chunk, "connection closed"
        out += chunk
    return out


def test_an_endless_frame_costs_no_memory_and_is_answered_4() -> None:
    emu = Emulator("--model", "GVE84-100", "--tcp", "127.0.0.1:0")
    try:
        sock = socket.create_connection(tuple(emu.first.split()[1].rsplit(":", 1)), 10)
        sock.sendall(b"!0?\r")
        assert read_answer(sock) == b"0,IP84 v3 27.1.2010\r"
        before = rss_kib(emu.proc.pid)
        block = b"A" * MB
        sock.sendall(b"!0V")
        for _ in range(32):                       # 32 MB without CR, with no pause
            sock.sendall(block)
        sock.sendall(b"\r")
        assert read_answer(sock) == b"4\r"        # longer than 96 bytes (spec 3)
        assert rss_kib(emu.proc.pid) - before < 8 * 1024, "the frame was buffered"
        sock.sendall(b"!0@\r")
        assert read_answer(sock) == b"0,2\r"      # ? and the long frame counted
        sock.close()
    finally:
        assert emu.stop() == 0


def test_a_host_that_closes_and_connects_again_at_once_is_served() -> None:
    emu = Emulator("--model", "GVE84-100", "--tcp", "127.0.0.1:0")
    where = tuple(emu.first.split()[1].rsplit(":", 1))
    deadline = time.monotonic() + 60
    try:
        for i in range(200):
            sock = socket.create_connection(where, 10)
            try:
                sock.sendall(b"!0?\r")
                assert read_answer(sock) == b"0,IP84 v3 27.1.2010\r", f"cycle {i}"
            finally:
                sock.close()
        assert time.monotonic() < deadline
    finally:
        assert emu.stop() == 0


def test_a_host_that_stops_reading_stops_neither_the_unit_nor_the_control_channel() -> None:
    emu = Emulator("--model", "GVE84-100", "--pty")
    port = serial.Serial(emu.first, 115200, timeout=5, write_timeout=5)
    try:
        t0 = emu.state()["time_ns"]
        frames = b"!0V1000\r" * 4000
        for _ in range(12):                       # 96,000 answers nobody reads
            port.write(frames)
        deadline = time.monotonic() + 10
        state = emu.state()                       # the controller is answered meanwhile
        assert time.monotonic() < deadline
        assert state["time_ns"] > t0 and state["index"] > 0
        port.reset_input_buffer()
        port.write(b"!0?\r")
        for _ in range(200000):                   # lost answers aside, it still answers
            line = port.read_until(b"\r")
            assert line, "no answer any more"
            if line.startswith(b"0,IP84"):
                break
    finally:
        port.close()
        assert emu.stop() == 0


def test_control_lines_are_read_as_they_come() -> None:
    emu = Emulator("--model", "GVE84-100", "--pty")
    port = serial.Serial(emu.first, 115200, timeout=5)
    try:
        emu.send("sta")                           # a partial line blocks nothing
        port.write(b"!0?\r")
        assert port.read_until(b"\r") == b"0,IP84 v3 27.1.2010\r"
        emu.send("te\nin 1 FE\nstate\n")          # three lines in one write: three replies
        assert emu.readline(10).startswith("{")
        assert emu.readline(10) == "ok"
        assert '"1": "FE"' in emu.readline(10)
        assert emu.control("quit now").startswith("error:")    # quit takes no arguments
        assert emu.control("quit @0").startswith("error:")
        emu.send("quit\n")
        assert emu.proc.wait(10) == 0
    finally:
        port.close()
        if emu.proc.poll() is None:
            emu.stop()


def test_eeprom_writes_leave_no_temporary_file_also_when_interrupted(tmp_path: Path) -> None:
    image = tmp_path / "unit.eeprom"
    rnd = random.Random(9)
    for attempt in range(3):
        emu = Emulator("--model", "GVE84-100", "--pty", "--eeprom", str(image))
        port = serial.Serial(emu.first, 115200, timeout=5)
        frames = b"".join(b"!0EW%02X,%02X\r" % (i, attempt) for i in range(0x40, 0x80))
        port.write(frames)
        time.sleep(rnd.uniform(0.0, 0.05))       # interrupt somewhere in the writes
        emu.proc.send_signal(rnd.choice([signal.SIGINT, signal.SIGTERM]))
        assert emu.proc.wait(10) == 0
        port.close()
        assert [p.name for p in tmp_path.iterdir()] == ["unit.eeprom"]
        assert len(image.read_bytes()) == 256


def test_two_units_answering_one_address_are_refused() -> None:
    with pytest.raises(serial.SerialException, match="address 7"):
        serial.serial_for_url("gve://?unit=GVE114-500@0&unit=GVE84-100@7")
    with pytest.raises(serial.SerialException, match="address 1"):
        serial.serial_for_url("gve://?unit=GVE54@1&unit=GVE84-100@1")


def test_a_stream_of_lone_bangs_costs_linear_time() -> None:
    port = serial.serial_for_url("gve://?model=GVE84-100&baud=921600", timeout=0)
    deadline = time.monotonic() + 30              # quadratic would take hours
    port.write(b"!" * MB)
    port.write(b"\r!0@\r")
    assert time.monotonic() < deadline
    port.timeout = 1
    assert port.read_until(b"\r") == b"0,0\r"     # only '!' arrived: nothing counted


def test_time_beyond_the_clock_is_a_clear_error() -> None:
    port = serial.serial_for_url("gve://?model=GVE84-100", timeout=1)
    with pytest.raises(TimeRangeError, match="73 years"):
        port.line.advance(100 * 365 * 86400)
    port.timeout = 3e9
    with pytest.raises(TimeRangeError):
        port.read(1)
    port.timeout = 1
    port.write(b"!0?\r")                           # the line is still usable
    assert port.read_until(b"\r") == b"0,IP84 v3 27.1.2010\r"


def test_the_closed_pipe_of_head_ends_the_emulator_quietly() -> None:
    emu = Emulator("--model", "GVE84-100", "--pty", stdin=None)
    os.close(emu.proc.stdout.fileno())            # what `| head -1` does after one line
    emu.proc.stdout = None
    assert emu.proc.wait(10) == 0
    assert emu.stderr() == ""
