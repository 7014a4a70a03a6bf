"""The suite's own framing against the spec's worked examples (spec 4, 6)."""

from __future__ import annotations

from conformance.link.framing import byte_sum, frame, parse_response


def test_checksums_of_the_manual():
    assert byte_sum(b"!0A100,") == 0x4F
    assert byte_sum(b"0,") == 0x5C
    assert byte_sum(b"0,10,") == 0xE9
    assert byte_sum(b"!0%-,") == 0xCF


def test_frames():
    assert frame("A100") == b"!0A100\r"
    assert frame("A100", checksum=True) == b"!0A100,4F\r"
    assert frame("PF", 1) == b"!1PF\r"
    assert frame("A100", checksum="00") == b"!0A100,00\r"


def test_responses():
    r = parse_response(b"0,10,E9\r", summed=True)
    assert (r.code, r.inta, r.values, r.checksum_ok, r.well_formed) == (0, False, ["10"], True,
                                                                        True)
    r = parse_response(b"8,D0\r", summed=False)
    assert (r.code, r.inta, r.values) == (0, True, ["D0"])
    assert parse_response(b"C\r", summed=False).code == 4
    assert parse_response(b"0,10,E8\r", summed=True).checksum_ok is False
    assert not parse_response(b"0,1", summed=False).well_formed
    assert not parse_response(b"x\r", summed=False).well_formed
    two = parse_response(b"!0T99\r5\r", summed=False, lines=2)
    assert two.lines == [b"!0T99", b"5"] and two.code == 5
