"""The wire's own pieces: a response read through its helpers (code, INTA, ST6, hex
fields), and the framer as the link uses it (frames only, state kept or not)."""

from __future__ import annotations

import pytest

from conformance.protocol.framer import HostFramer
from conformance.protocol.wire import UnitDataError, is_hex_byte, parse_response
from gve_fixtures.protocol import ErrorCode, St6


def test_a_response_names_its_code_and_reads_st6():
    r = parse_response(b"8,C0\r", summed=False)
    assert r.code == 0 and r.inta and r.ok and r.error is ErrorCode.OK
    assert r.st6() == St6.RUN | St6.INTA
    refused = parse_response(b"5\r", summed=False)
    assert refused.error is ErrorCode.RANGE and not refused.ok
    assert parse_response(b"", summed=False).error is None


def test_a_field_that_is_not_two_hex_digits_is_the_units_fault():
    with pytest.raises(UnitDataError):
        parse_response(b"0,C\r", summed=False).st6()


def test_a_hex_byte_is_two_digits_upper_case_unless_either_case_is_allowed():
    assert is_hex_byte("00") and is_hex_byte("C0") and is_hex_byte("FF")
    assert not any(is_hex_byte(t) for t in ("c0", "C", "C00", "G0", "", " C", "-1"))
    assert is_hex_byte("c0", either_case=True) and is_hex_byte("aF", either_case=True)
    assert not is_hex_byte("g0", either_case=True)


def test_frames_as_the_link_reads_them():
    framer = HostFramer()
    assert framer.frames(b"noise!0L1,2", commit=False) == []
    assert framer.frames(b"!0L1,2,3\r\n!1SW6,80,", commit=False)[0].text == "L1,2,3"
    assert framer.frames(b"!0*S\r!0C1") and framer.out == []
    (f,) = framer.frames(b",0,0\r")
    assert (f.address, f.text, f.wire) == (0, "C1,0,0", b"!0C1,0,0\r")
    assert f.bodies(True) == ["C1,0,0"] and f.bodies(None) == ["C1,0,0"]
    (g,) = HostFramer().frames(b"!0@,40\r")
    assert g.bodies(None) == ["@,40", "@"] and g.bodies(False) == ["@,40"]


def test_a_bang_restarts_an_unfinished_frame():
    (f,) = HostFramer().frames(b"!0L1!0H\r")
    assert f.text == "H"
