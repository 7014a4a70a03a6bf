"""What the read-back machine reads back by a move from rest (spec 10)."""

from __future__ import annotations

import pytest

from conformance.machines.readback import _touches_motion


@pytest.mark.parametrize("body", ["V700", "V1000,5", "A0", "A5", "VL5,5,5", "XM0", "XM100"])
def test_a_frame_that_paces_a_lone_vector_touches_the_motion(body):
    assert _touches_motion(body)


@pytest.mark.parametrize("body", ["VK", "VN", "V+1", "T24", "B500", "$10", "L5,0,0", "Z"])
def test_a_switch_a_sign_or_what_acts_between_vectors_does_not(body):
    assert not _touches_motion(body)
