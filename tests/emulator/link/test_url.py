"""The gve:// pyserial URL: parsing, and a port that behaves like a serial port in
virtual time (answers from the spec's identification table, timeouts in virtual seconds)."""

from __future__ import annotations

import time

import pytest
import serial

import emulator  # noqa: F401  (registers gve://)
from emulator.link.url import parse_url
from gve_fixtures.protocol import SECOND
from gve_fixtures.transcript import HOST, UNIT, load


def test_parse_model_and_address() -> None:
    spec = parse_url("gve://?model=GVE54&address=3&baud=19200&watchdog_ms=250&mutant=x")
    assert spec.units == [("GVE54", 3)]
    assert (spec.baud, spec.watchdog_ms, spec.mutant) == (19200, 250, "x")


def test_parse_repeated_units_and_defaults() -> None:
    assert parse_url("gve://?unit=GVE54@1&unit=GVE84-100@0").units == [
        ("GVE54", 1), ("GVE84-100", 0)]
    spec = parse_url("gve://")
    assert spec.units == [("GVE84-100", None)] and spec.baud is None


@pytest.mark.parametrize("url", ["gve://?colour=red", "socket://x:1", "gve://?baud=fast"])
def test_bad_urls_are_refused(url: str) -> None:
    with pytest.raises(ValueError):
        parse_url(url)


def test_bad_url_through_pyserial_is_a_serial_exception() -> None:
    with pytest.raises(serial.SerialException):
        serial.serial_for_url("gve://?colour=red")


def test_identification_through_serial_for_url() -> None:
    port = serial.serial_for_url("gve://?model=GVE84-100&address=0", timeout=1.0)
    assert isinstance(port, serial.SerialBase)
    assert port.line.baud == port.baudrate
    port.write(b"!0?\r")
    assert port.read_until(b"\r") == b"0,IP84 v3 27.1.2010\r"     # spec table, [D]
    port.close()


def test_timeout_is_virtual_seconds() -> None:
    port = serial.serial_for_url("gve://?model=GVE84-100", timeout=30.0)
    start = port.line.now
    assert port.read(1) == b""                  # nobody talks unasked
    assert port.line.now - start == 30 * SECOND
    assert port.in_waiting == 0


def test_two_units_share_one_line() -> None:
    port = serial.serial_for_url("gve://?unit=GVE54@1&unit=GVE84-100@0", timeout=1.0)
    port.write(b"!1?\r")
    assert port.read_until(b"\r") == b"0,Ip54v3 21.12.2007\r"
    port.write(b"!0?\r")
    assert port.read_until(b"\r") == b"0,IP84 v3 27.1.2010\r"


def test_log_parameter_writes_a_transcript(tmp_path) -> None:
    path = tmp_path / "wire.gvt"
    port = serial.serial_for_url(f"gve://?model=GVE84-100&log={path}", timeout=1.0)
    port.write(b"!0?\r")
    port.read_until(b"\r")
    port.close()
    records = load(path).records
    assert [(r.direction, r.data) for r in records] == [
        (HOST, b"!0?\r"), (UNIT, b"0,IP84 v3 27.1.2010\r")]


def test_realtime_port_answers_on_the_wall_clock() -> None:
    port = serial.serial_for_url("gve://?model=GVE84-100&realtime=1", timeout=2.0)
    assert not port.line.clock.virtual
    start = time.monotonic()
    port.write(b"!0?\r")
    assert port.read_until(b"\r") == b"0,IP84 v3 27.1.2010\r"
    port.timeout = 0.05
    assert port.read(1) == b""
    assert 0.05 <= time.monotonic() - start < 2.0
