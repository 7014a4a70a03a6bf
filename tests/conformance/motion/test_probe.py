"""How the motion probe reads the frames of its script (spec 10)."""

from __future__ import annotations

import pytest

from conformance.motion.probe import _split


@pytest.mark.parametrize(("body", "read"), [
    ("L600,0,0", ("L", "600,0,0")), ("C-700,0,0", ("C", "-700,0,0")),
    ("V1500", ("V", "1500")), ("VL25000,25000,30000", ("VL", "25000,25000,30000")),
    ("VK", ("VK", "")), ("VN", ("VN", "")), ("XM200", ("XM", "200")), ("XA", ("XA", "")),
    ("$1", ("$", "1")), ("T24", ("T", "24")), ("MF", ("M", "F")), ("H", ("H", "")),
])
def test_a_frame_is_read_as_its_command_and_the_rest(body, read):
    assert _split(body) == read
