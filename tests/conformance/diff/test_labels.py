"""Labels name rules that exist and pick the most specific one."""

from conformance.diff.labels import allowed, command_of, label, load_labels, verdict_of
from conformance.verdict import FAIL, INFO, NON_STRICT
from gve_fixtures.rules import load_rules


def test_every_label_names_a_known_rule():
    rules = load_rules()
    assert load_labels() and all(entry.rule in rules for entry in load_labels())


def test_command_names_are_read_longest_first():
    assert command_of("PF") == "PF" and command_of("P") == "P"
    assert command_of("SW6,80") == "SW6" and command_of("SW0,01") == "SW"
    assert command_of("q") == "Q" and command_of("*E2") == "*E"


def test_context_before_command():
    assert label("?", "code", {"lower"}, set(), 0) == "3.frame.upper-case"
    assert label("SR", "code", set(), set(), 5, 4) == "5.code.range"
    assert label("PF", "position", set(), {"L", "V"}, 0) == "10.2.motion.dominant-rate"
    assert label("PF", "position", set(), {"L", "G", "H"}, 0) == "10.4.go.resume"


def test_grading_follows_the_rule_tag():
    assert verdict_of("5.code.range", False)[0] == FAIL               # M-ex
    assert verdict_of("10.5.restore.pops", False)[0] == NON_STRICT    # D
    assert verdict_of("10.5.restore.pops", True)[0] == FAIL           # D, decisions kept
    assert verdict_of(None, True) == (INFO, "D-info")


def test_a_difference_within_the_dwell_is_the_dwell():
    # an H answered at another instant: the halt's ramp, unless the vector was in its T
    assert label("H", "timing", set(), {"L"}, 0) == "10.4.halt.ramp"
    assert label("H", "timing", {"in-dwell"}, {"L"}, 0) == "10.2.motion.dwell"


def test_a_modal_setting_the_sequence_needs_wins_over_the_command_and_packet():
    # an L refused on one side only: the queue rule, unless a rate set earlier decides
    # when the vector before it ends
    assert label("L", "code", set(), {"L"}, 3, 0) == "10.1.queue.line-alone"
    assert label("L", "code", set(), {"L", "VL"}, 3, 0) == "10.2.motion.axis-caps"
    assert label("P", "position", set(), {"L", "XU", "*S", "*E"}, 0) == \
        "10.cmd.exchange-velocity"


def test_a_position_after_go_is_the_resume_even_after_restore():
    assert label("PF", "position", set(), {"L", "H", "K", "R", "G"}, 0) == "10.4.go.resume"
    assert label("SR", "data", set(), {"L", "H", "K", "R"}, 0) == "10.5.restore.exact"


def test_a_plus_sign_or_a_lower_case_digit_names_the_parameter_rule():
    assert label("ER", "code", {"plus"}, set(), 4, 0) == "3.params.hex-digits"
    assert label("T", "code", {"plus"}, set(), 4, 0) == "3.params.decimal"
    assert label("EW", "code", {"lower-param"}, set(), 0, 4) == "3.params.hex-digits"
    # only the command's own letters make it the upper-case rule
    assert label("EW", "code", {"lower"}, set(), 3, 0) == "3.frame.upper-case"


def test_the_index_off_by_the_queries_is_the_counting_rule():
    assert label("@", "data", {"queries-counted"}, {"@"}, 0) == "8.index.queries-uncounted"
    assert label("@", "data", set(), {"@", "L"}, 0) == "8.index.counts"


def test_the_firmware_string_is_the_version_rule():
    assert label("?", "data", set(), set(), 0) == "1.profile.version"


def test_both_answers_allowed_by_the_spec_are_no_finding():
    assert allowed("G", "code", set(), {"H", "K"}, 0, 6)
    assert allowed("G", "code", set(), set(), 6, 0) is None      # G with INTA = 0 → 6 [M]
    assert allowed("NA", "code", set(), set(), 3, 5)
    assert allowed("L", "code", set(), set(), 3, 5) is None


def test_a_breaker_unanswered_inside_a_packet_is_the_breakers_rule():
    # a unit that closes a packet only with *E takes H, @, >, J as members
    for command in ("H", "@", ">", "J"):
        assert label(command, "silence", {"in-packet"}, {"*S"}, 0) == "7.packet.breakers"
    assert label("H", "silence", {"bad-checksum", "in-packet"}, {"*S"}, 4) == \
        "7.packet.bad-checksum-member"


def test_a_repeat_after_an_index_is_whether_the_index_is_remembered():
    assert label(">", "data", set(), {"V", "@"}, 0, 0) == "8.repeat.remembered"
    assert label(">", "data", set(), {"V"}, 0, 0) == "8.repeat.answer"


def test_what_a_stated_rule_isolates_names_it_not_the_decision_beside_it():
    # a VL that capped only axes the motion never moved: another axis's value held it
    assert label("PF", "position", {"capped-elsewhere"}, {"VL", "L"}, 0) == \
        "10.cmd.axis-limits-own-axis"
    assert label("PF", "position", set(), {"VL", "L"}, 0) == "10.2.motion.axis-caps"
    # GVE54: beyond where the vectors could go is the mode's step, short of it its rates
    assert label("PF", "position", {"beyond-reach"}, {"M", "L"}, 0) == "10.7.motor.modes"
    assert label("PF", "position", set(), {"M", "L"}, 0) == "10.7.motor.rates-scaled"
    # a status word read back otherwise after a refused write: the refusal stored it
    assert label("SR", "data", set(), {"SW", "SW-refused"}, 0) == \
        "4.response.failed-not-executed"
    assert label("SR", "data", set(), {"SW"}, 0) == "10.3.status.all-bits"
    # a motion after a V or an A the reference refused: the refusal set it
    assert label("PF", "position", set(), {"V", "V-refused", "L"}, 0) == \
        "4.response.failed-not-executed"
    assert label("PF", "position", set(), {"A", "L"}, 0) == "10.2.motion.trapezoid"
    # ST6 read after the MPG's enable byte was written (or the MPG switched): whether the
    # MPG holds RUN is that byte's; after a vector alone, whether the unit took it
    assert label("SR", "data", set(), {"EW", "J", "L"}, 0) == "9.reset.mpg"
    assert label("F", "data", set(), {"Y"}, 0) == "9.reset.mpg"
    assert label("SR", "data", set(), {"L"}, 0) == "10.cmd.vector"


def test_an_input_interrupting_is_the_manuals_and_when_it_does_the_decision():
    # where the axes are after an input: it stopped them, or not (M84 12.5.11)
    assert label("PF", "position", set(), {"input", "SW"}, 0) == "10.3.inputs.interrupt"
    assert verdict_of("10.3.inputs.interrupt", False)[0] == FAIL
    # an input still active when G, D or an SW clears, or when an SW enables it: whether
    # that interrupts again is when inputs interrupt
    for command in ("G", "D", "SW", "SW6"):
        assert label(command, "inta", set(), {"input"}, 0) == "10.3.inputs.level-triggered"
    assert label("SW", "inta", {"enables"}, {"SW"}, 0) == "10.3.inputs.level-triggered"
    assert label("SW", "inta", set(), {"SW"}, 0) == "4.response.inta-bit"


def test_a_clear_with_an_input_its_polarity_made_active_is_when_inputs_interrupt():
    for command in ("G", "D", "K", "R", "SW6"):
        assert label(command, "inta", set(), {"SW"}, 0) == "10.3.inputs.level-triggered"


def test_a_stalled_repeat_run_whole_is_the_watchdogs_time():
    # the reference's watchdog answered 2 (one line) where `>` run whole answered others
    assert label(">", "bytes", {"stalled"}, set(), None, None) == "3.frame.watchdog-time"
    assert label("?", "silence", {"stalled"}, set(), 2, None) == "3.frame.watchdog"
