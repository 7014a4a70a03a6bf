"""What the read-back machine reads back by each effect (spec 10, 10.2, 10.7), and the
rule a range refusal is checked by."""

from __future__ import annotations

import pytest

from conformance.machines.readback import REFUSALS, SPINDLE, effect_of, range_rule
from gve_fixtures.profile import load_profile


@pytest.mark.parametrize("body", ["V700", "V1000,5", "A0", "A5", "VL5,5,5", "XM0", "XM100"])
def test_a_frame_that_paces_a_lone_vector_is_read_by_a_move_from_rest(body):
    assert effect_of(body) == "pace"


@pytest.mark.parametrize(("body", "effect"), [("B5", "junction"), ("B700,5", "junction"),
                                              ("T99", "dwell"), ("T20,5", "dwell"),
                                              ("M4,5", "microstep"), ("MF", "microstep")])
def test_b_t_and_the_micro_step_mode_are_read_by_their_own_effect(body, effect):
    assert effect_of(body) == effect


@pytest.mark.parametrize("body", ["VK", "VN", "V+1", "$10", "L5,0,0", "Z", "SW2,1A5"])
def test_a_switch_a_sign_or_what_sets_nothing_a_probe_reads_has_no_effect(body):
    assert effect_of(body) is None


@pytest.mark.parametrize(("profile", "rule"), [("GVE54", "1.profile.v-b-range-gve54"),
                                               ("GVE84-100", "1.profile.v-b-range"),
                                               ("GVE114-500", "1.profile.v-b-range")])
def test_a_b_out_of_range_is_held_to_the_profiles_own_range_rule(profile, rule):
    assert range_rule("B5", load_profile(profile)) == rule


def test_a_range_refusal_with_no_rule_of_its_command_is_a_range_code():
    assert range_rule("XM0", load_profile("GVE84-100")) == "5.code.range"


def test_every_setting_a_probe_reads_has_a_refusal_that_would_set_it():
    bodies = [r.body for r in REFUSALS if r.address != SPINDLE]
    assert {effect_of(b) for b in bodies} - {None} == {"pace", "junction", "dwell",
                                                      "microstep"}
    assert any(r.address == SPINDLE for r in REFUSALS)


def test_only_a_hex_field_of_three_digits_may_be_refused_as_syntax_instead():
    from conformance.protocol.parse import parse
    from gve_fixtures.protocol import ErrorCode
    also = {r.body for r in REFUSALS if ErrorCode.SYNTAX in r.also}
    assert also == {"O0,1A5", "SW2,1A5"}
    assert all(max(len(f) for f in parse(b).fields) == 3 for b in also)
