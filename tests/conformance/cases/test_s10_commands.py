"""The reference cases' arithmetic of how far a W ran, judged by its answer."""

from __future__ import annotations

from conformance.cases.s10_commands import _ran
from conformance.link.framing import parse_response


def test_a_w_answered_5_ran_its_whole_travel():
    assert _ran(parse_response(b"5\r", summed=False), 50) == 50


def test_a_w_answered_0_ran_at_least_the_step_that_released_its_switch():
    # a unit that reads another input as the switch, or releases it one step back
    assert _ran(parse_response(b"0\r", summed=False), 50) == 1
    assert _ran(None, 50) == 1
