"""The reference host's frames and answers, against the spec's own examples (spec 6)."""

from __future__ import annotations

from gve_host.wire import frame, parse


def test_frames_with_and_without_checksums():
    assert frame(0, "A100", False) == b"!0A100\r"
    assert frame(0, "A100", True) == b"!0A100,4F\r"            # spec 6, G2
    assert frame(0, "%-", True) == b"!0%-,CF\r"                # spec 6, G1
    assert frame(3, "V10", False, end=b"\n") == b"!3V10\n"


def test_answers():
    a = parse(b"0,5C\r", True)                                  # spec 6
    assert a is not None and (a.code, a.inta, a.values) == (0, False, ())
    a = parse(b"0,10,E9\r", True)                               # spec 7, G3
    assert a is not None and a.values == ("10",)
    a = parse(b"8\r", False)                                    # OK, but interrupted
    assert a is not None and (a.code, a.inta) == (0, True)
    a = parse(b"9\r", False)
    assert a is not None and (a.code, a.inta) == (1, True)


def test_damaged_answers_are_not_taken():
    assert parse(b"0,5D\r", True) is None                       # the sum does not add up
    assert parse(b"0\r", True) is None                          # no checksum in the mode
    assert parse(b"\x00\xff0\r", False) is None                 # noise before it
    assert parse(b"\xb0\r", False) is None                      # a broken bit
    assert parse(b"G\r", False) is None                         # no code digit
    assert parse(b"0,5D\r", True, trust_checksum=True) is not None
