"""The units played to a host: the reference emulator through its public URL, taking the
readings a host was written for."""

from __future__ import annotations

import pytest

from conformance.host.played_units import check_readings, load_units, open_line


def _index_after(frames: int, readings: tuple[str, ...]) -> bytes:
    line = open_line(load_units(["GVE54"]), 19200, readings)
    line.timeout = 1.0                  # on the line's own clock: no real time passes
    try:
        for _ in range(frames):
            line.write(b"!0?\r")
            line.read_until(b"\r")
        line.write(b"!0@\r")
        return line.read_until(b"\r")
    finally:
        line.close()


def test_the_played_unit_takes_the_reading_given():
    # eleven frames: the index is 11, written 11 by the project's decision, 0B in hex
    assert _index_after(11, ()).rstrip(b"\r").endswith(b",11")
    assert _index_after(11, ("index-hex",)).rstrip(b"\r").upper().endswith(b",0B")


def test_an_unknown_reading_is_refused_with_the_known_ones():
    assert check_readings(["index-hex"]) == ("index-hex",)
    with pytest.raises(ValueError, match=r"index-hx.*known:.*index-hex"):
        check_readings(["index-hx"])
