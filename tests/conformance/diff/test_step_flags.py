"""The context flags a difference's labels read off its step alone."""

import pytest

from conformance.diff.labels import command_of
from conformance.diff.step_flags import axis_comma, long_hex, step_flags
from conformance.diff.steps import FRAME, Step
from conformance.protocol.parse import parse as parse_frame
from gve_fixtures.profile import load_profile

GVE114 = load_profile("GVE114-500")


@pytest.mark.parametrize(("body", "long"), [("SW2,1A5", True), ("ER00D", True),
                                           ("EW100,00", True), ("O0,100", True),
                                           ("SW2,FF", False), ("ERD", False),
                                           ("V1000", False), ("NA100", False)])
def test_a_hex_field_longer_than_the_manuals_two_digits_is_its_context(body, long):
    assert long_hex(command_of(body), parse_frame(body).fields) is long


def test_a_w_with_a_comma_after_its_axis_and_its_numbers_in_range_is_its_context():
    assert axis_comma("WX,-100,1000,50,1000")
    assert not axis_comma("WX-100,1000,50,1000")
    # a field out of range: the reference's 5 is the range's, the target's 4 its bug
    assert not axis_comma("WX,1,900,-1,900")
    assert not axis_comma("WX,1,900,1")


def test_a_step_s_address_case_and_checksum_are_its_flags():
    spindle = GVE114.spindle.address
    assert "to-spindle" in step_flags(Step(FRAME, "V10", address=spindle), GVE114,
                                      in_packet=False, summing=False)
    assert "other-address" in step_flags(Step(FRAME, "V10", address=3), GVE114,
                                         in_packet=False, summing=False)
    assert {"lower", "in-packet"} <= step_flags(Step(FRAME, "v10"), GVE114, in_packet=True,
                                                summing=False)
    bad = Step(FRAME, "V10", checksum="bad")
    assert "bad-checksum" in step_flags(bad, GVE114, in_packet=False, summing=True)
    assert "bad-checksum" not in step_flags(bad, GVE114, in_packet=False, summing=False)


def test_a_space_among_the_parameters_is_its_context():
    assert "space" in step_flags(Step(FRAME, "SW 6,00"), GVE114, in_packet=False,
                                 summing=False)
    assert "space" not in step_flags(Step(FRAME, "SW6,00"), GVE114, in_packet=False,
                                     summing=False)
