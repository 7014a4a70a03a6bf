"""Labels name rules that exist and pick the most specific one."""

import pytest

from conformance.diff.labels import allowed, command_of, label, load_labels, verdict_of
from conformance.verdicts.verdict import FAIL, INFO, NON_STRICT
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
    assert label("L", "code", set(), {"L"}, 1, 0) == "10.1.queue.line-alone"
    assert label("L", "code", set(), {"L", "VL"}, 1, 0) == "10.2.motion.axis-caps"
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


def test_a_space_among_the_parameters_refused_as_syntax_is_the_decimal_rule():
    assert label("SW6", "code", {"space"}, set(), 4, 0) == "3.params.decimal"


def test_the_hand_wheel_sent_on_while_eeprom_06_does_not_enable_it_is_the_inert_rule():
    assert label("SR", "data", {"mpg-disabled"}, {"Y"}, 0, 0) == "9.reset.mpg-inert"
    assert label("L", "code", {"mpg-disabled"}, {"Y"}, 0, 7) == "9.reset.mpg-inert"


def test_n_axis_refused_after_a_halt_by_the_reference_only_is_the_run_decision():
    assert label("NX", "code", set(), {"C", "H"}, 7, 0) == "5.code.busy-run-decided"


def test_three_hex_digits_refused_as_syntax_are_the_hex_digits_rule():
    assert label("SW", "code", {"long-hex"}, set(), 5, 4) == "3.params.hex-digits"
    assert label("ER", "code", {"long-hex"}, set(), 0, 4) == "3.params.hex-digits"
    # a two-digit field out of range answered 4 is still the range rule
    assert label("SW", "code", set(), set(), 5, 4) == "5.code.range"


def test_w_with_a_comma_after_the_axis_refused_as_syntax_is_the_w_syntax_rule():
    # the reference ran it and found no switch (5): the target's 4 is still the form's
    assert label("W", "code", {"axis-comma"}, set(), 5, 4) == "10.cmd.reference-syntax"
    assert label("W", "code", set(), set(), 5, 4) == "5.code.range"


def test_na_refused_is_the_a_axis_decision_on_the_gve114_only():
    assert label("NA", "code", set(), set(), 5, 4, "GVE114") == "10.cmd.set-axis-a"
    assert label("NX", "code", set(), set(), 0, 4, "GVE114") == "5.code.ok"


def test_the_index_off_by_the_queries_is_the_counting_rule():
    assert label("@", "data", {"queries-counted"}, {"@"}, 0) == "8.index.queries-uncounted"
    assert label("@", "data", set(), {"@", "L"}, 0) == "8.index.counts"


def test_the_index_short_by_the_refused_frames_is_that_readings_rule():
    assert label("@", "data", {"refused-uncounted"}, {"T-refused"}, 0) == \
        "8.index.refused-counted"


def test_the_index_written_in_hex_is_its_form_rule():
    assert label("@", "data", {"index-hex"}, {"V"}, 0) == "8.index.decimal"


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


def test_what_a_unit_does_in_the_t_dwell_after_l0_0_0_is_the_zero_vectors_reading():
    # a unit holding RUN for T after L0,0,0 (a normal vector to a reader of the manual)
    assert label("F", "data", {"after-zero-vector", "st6-run"}, {"L"}, 0, 0) == \
        "10.2.motion.zero-length"
    assert label("N", "code", {"after-zero-vector"}, {"L"}, 0, 7) == "10.2.motion.zero-length"
    assert label("F", "data", {"st6-run"}, {"L"}, 0, 0) != "10.2.motion.zero-length"


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


def test_the_inta_of_an_sw6_answer_is_the_writes_own_decision():
    assert label("SW6", "inta", set(), set(), 0) == "10.3.sw6.answer-inta"
    assert verdict_of("10.3.sw6.answer-inta", False)[0] == NON_STRICT
    # an answer after it: what the write did, the write's rule
    assert label("V", "inta", set(), {"SW6"}, 0) == "10.3.sw6.acts"
    # any other answer's INTA bit stays the manual's
    assert label("V", "inta", set(), set(), 0) == "4.response.inta-bit"


def test_a_clear_with_an_input_its_polarity_made_active_is_when_inputs_interrupt():
    for command in ("G", "D", "K", "R", "SW6"):
        assert label(command, "inta", set(), {"SW"}, 0) == "10.3.inputs.level-triggered"


def test_a_stalled_repeat_run_whole_is_the_watchdogs_time():
    # the reference's watchdog answered 2 (one line) where `>` run whole answered others
    assert label(">", "bytes", {"stalled"}, set(), None, None) == "3.frame.watchdog-time"
    assert label("?", "silence", {"stalled"}, set(), 2, None) == "3.frame.watchdog"


#: one behaviour, one grade: for every rule the catalogue grades a behaviour by and diff
#: labels a disagreement with, that behaviour as diff sees it — (the case that grades
#: it, then the facts: command, kind, context, earlier, reference's and target's codes,
#: family) — and diff must name the same rule
PAIRS: dict[str, tuple[str, tuple]] = {
    # the firmware string answered otherwise
    "1.profile.version": ("1.profile.version", ("?", "data", set(), set(), 0, 0)),
    # C into a full queue taken, or C refused with room
    "10.1.queue.cont-buffer": ("5.errors.queue-full", ("C", "code", set(), {"C"}, 1, 0)),
    # GVE54: a halted vector's remainder after an M taken while it was held
    # a C refused (1) while an L runs, which the reference queued behind it
    "10.1.queue.c-behind-line": ("10.1.cont.behind-line",
                                 ("C", "code", set(), {"L"}, 0, 1)),
    "10.1.queue.captured": ("10.1.measured.captured",
                            ("PF", "position", {"mode-over-held"}, {"M", "H", "C"}, 0, 0)),
    # L while a vector runs taken
    "10.1.queue.line-alone": ("5.errors.refused-not-executed",
                              ("L", "code", set(), {"L"}, 1, 0)),
    # where a vector under VL is
    "10.2.motion.axis-caps": ("10.2.measured.axis-caps",
                              ("PF", "position", set(), {"VL", "L"}, 0, 0)),
    "10.2.motion.dominant-rate": ("10.2.measured.cruise-at-v",
                                  ("PF", "position", set(), {"V", "L"}, 0, 0)),
    # what a vector with no motion holds: RUN within the T dwell after L0,0,0
    "10.2.motion.zero-length": ("10.2.measured.zero-length-c",
                                ("F", "data", {"after-zero-vector", "st6-run"}, {"L"}, 0, 0)),
    # R refused as busy while halted vectors hold RUN: taken after H by the reference
    "5.moving.after-halt": ("5.errors.n-while-run",
                            ("R", "code", set(), {"H", "K", "L"}, 0, 7)),
    "10.2.motion.junction-reversal": ("10.2.measured.junction-reversal",
                                      ("PF", "position", {"reversal"}, {"C", "junction"},
                                       0, 0)),
    "10.2.motion.dwell": ("10.2.measured.dwell",
                          ("PF", "position", {"in-dwell"}, {"L"}, 0, 0)),
    "10.2.motion.junction": ("10.2.measured.junction",
                             ("PF", "position", set(), {"C", "junction"}, 0, 0)),
    "10.2.motion.path-rate": ("10.2.measured.path-rate",
                              ("PF", "position", set(), {"VK", "L"}, 0, 0)),
    "10.2.motion.positions-now": ("10.2.measured.cruise-at-v",
                                  ("PF", "position", set(), {"L"}, 0, 0)),
    "10.2.motion.short-vector": ("10.2.measured.short-vector",
                                 ("PF", "position", set(), {"$", "L"}, 0, 0)),
    "10.2.motion.trapezoid": ("10.2.measured.trapezoid",
                              ("PF", "position", set(), {"A", "L"}, 0, 0)),
    # a grounded enabled input: the motion goes on
    "10.3.inputs.interrupt": ("10.3.interrupt.stops-motion",
                              ("PF", "position", set(), {"SW", "L", "input"}, 0, 0)),
    # D with the input still held: INTA again, or not
    "10.3.inputs.level-triggered": ("10.3.inputs.level-after-clearing",
                                    ("D", "code", set(), {"SW", "input"}, 0, 0)),
    "10.3.inputs.physical": ("10.3.inputs.physical-across-restart",
                             ("I1", "data", set(), {"J", "input"}, 0, 0)),
    "10.3.status.all-bits": ("10.3.status.all-bits-stored",
                             ("SR", "data", set(), {"SW"}, 0, 0)),
    "10.3.sw6.acts": ("10.3.sw6.writing-st6", ("PF", "position", set(), {"L", "SW6"}, 0, 0)),
    # SW6,01 answered 8 where the reference wrote STOP alone: the write's own answer
    "10.3.sw6.answer-inta": ("10.3.sw6.writing-st6", ("SW6", "inta", set(), set(), 0, 0)),
    "10.4.delete": ("10.4.delete.refused-while-moving", ("D", "code", set(), {"C"}, 7, 0)),
    "10.4.go.resume": ("10.4.go.resumes-exactly",
                       ("PF", "position", set(), {"L", "H", "G"}, 0, 0)),
    "10.4.go.without-inta": ("5.errors.go-without-inta", ("G", "code", set(), set(), 6, 0)),
    "10.4.halt.ramp": ("10.4.halt.answers-when-stopped",
                       ("H", "timing", set(), {"L"}, 0, 0)),
    "10.5.keep.c-refused": ("10.5.keep.single-l", ("C", "code", set(), {"K"}, 4, 0)),
    # a second K with a save held: refused
    "10.5.keep.one-level": ("10.5.keep.one-level",
                            ("K", "code", {"kept"}, {"H", "K"}, 0, 4, "GVE54")),
    "10.5.keep.one-level-info": ("10.5.keep.one-level",
                                 ("K", "code", {"kept"}, {"H", "K"}, 0, 4, "GVE84")),
    "10.5.keep.saves": ("10.5.keep.saves-st6",
                        ("SR", "data", {"kept"}, {"L", "H", "K"}, 0, 0)),
    "10.5.restore.exact": ("10.5.keep.partial-vector",
                           ("R", "code", {"kept"}, {"L", "H", "K"}, 0, 4)),
    # R with nothing kept refused, whatever the code
    "10.5.restore.pops": ("10.5.restore.empty", ("R", "code", {"nothing-kept"}, set(), 0, 5)),
    "10.6.eeprom.defaults": ("10.6.eeprom.as-shipped",
                             ("ER", "data", {"named"}, set(), 0, 0)),
    "10.6.eeprom.erased": ("10.6.eeprom.as-shipped",
                           ("ER", "data", {"unwritten"}, set(), 0, 0)),
    "10.6.eeprom.kept": ("10.6.eeprom.kept-across-restarts",
                         ("ER", "data", set(), {"EW", "J"}, 0, 0)),
    "10.7.motor.modes": ("10.7.microstep.positions-in-sixteenths",
                         ("PF", "position", {"beyond-reach"}, {"M", "L"}, 0, 0)),
    "10.7.motor.rates-scaled": ("10.7.measured.microstep-rates",
                                ("PF", "position", set(), {"M", "L"}, 0, 0)),
    "10.cmd.axis-limits-own-axis": ("10.cmd.measured.axis-limits-own-axis",
                                    ("PF", "position", {"capped-elsewhere"}, {"VL", "L"},
                                     0, 0)),
    "10.cmd.exchange-velocity": ("10.cmd.measured.exchange-xa",
                                 ("PF", "position", set(), {"C", "V", "XA"}, 0, 0)),
    "10.cmd.flags-after-keep": ("10.cmd.flags-after-keep.one-vector",
                                ("F", "data", {"kept"}, {"K", "L"}, 0, 0)),
    "10.cmd.inputs": ("10.3.status.inputs-read-ff", ("I1", "data", set(), set(), 0, 0)),
    "10.cmd.override": ("10.cmd.measured.override",
                        ("PF", "position", set(), {"L", "XM"}, 0, 0)),
    "10.cmd.port-bits": ("10.cmd.ports.bit-by-bit", ("I1", "data", set(), {"input"}, 0, 0)),
    "10.cmd.set-axis": ("10.commands.zero-axis", ("PF", "position", set(), {"NX"}, 0, 0)),
    # the GVE114's NA refused: its manual names the axes X, Y, Z
    "10.cmd.set-axis-a": ("10.commands.formats", ("NA", "code", set(), set(), 0, 4, "GVE114")),
    "12.spindle.feed-independent": ("12.spindle.measured.feed-unchanged",
                                    ("PF", "position", set(), {"spindle", "L"}, 0, 0)),
    "3.frame.other-address-whole": ("2.link.other-address-ignored",
                                    ("V", "silence", {"other-address"}, set(), None, 0)),
    "3.frame.upper-case": ("3.frame.lower-case-unknown", ("V", "code", {"lower"}, set(), 3, 0)),
    # a frame stalled past the watchdog: answered 2, or run whole by a slower watchdog
    "3.frame.watchdog": ("3.frame.watchdog", ("V", "silence", {"stalled"}, set(), 2, None)),
    "3.frame.watchdog-time": ("3.frame.watchdog", ("V", "code", {"stalled"}, set(), 2, 0)),
    "3.params.decimal": ("3.frame.syntax-errors", ("V", "code", {"plus"}, set(), 4, 0)),
    "3.params.hex-digits": ("3.params.hex-fields",
                            ("SW", "code", {"lower-param"}, set(), 0, 4)),
    "3.params.long-decimal": ("3.params.long-decimals",
                              ("T", "code", {"long-decimal"}, set(), 0, 4)),
    "3.params.none-expected": ("3.params.none-expected.given",
                               ("@", "code", {"extra-param"}, set(), 4, 0)),
    # a refused SW0,1FF stored
    "4.response.failed-not-executed": ("5.errors.refused-not-executed",
                                       ("SR", "data", set(), {"SW-refused"}, 0, 0)),
    "4.response.inta-bit": ("4.response.inta-bit", ("V", "inta", set(), {"H"}, 0, 0)),
    "5.code.busy-eeprom": ("10.6.eeprom.refused-while-moving",
                           ("EW", "code", set(), {"L"}, 7, 0)),
    "5.code.ok": ("5.errors.ok", ("L", "code", set(), set(), 0, 4)),
    # N<axis> refused with RUN = 1 held after H, nothing moving
    "5.code.busy-run-decided": ("5.code.busy-while-halted",
                                ("NX", "code", set(), {"C", "H"}, 7, 0)),
    "5.code.range": ("5.errors.out-of-range", ("SW", "code", set(), set(), 5, 4)),
    # the MPG holding RUN: D refused while it does
    "5.moving.definition": ("9.reset.mpg-enabled", ("D", "code", set(), {"EW", "J"}, 7, 0)),
    "6.checksum.bad-refused": ("6.checksum.bad-sum-rejected",
                               ("A", "code", {"bad-checksum"}, {"%"}, 4, 0)),
    "6.checksum.mode-commands": ("6.machine.checksum-framing",
                                 ("%", "code", set(), set(), 0, 4)),
    "6.checksum.response-sum": ("6.checksum.responses-summed",
                                ("SR", "checksum", set(), {"%"}, 0, 0)),
    # a failed packet's C ran (the reference refused its *E)
    "7.packet.all-or-nothing": ("7.packet.failed-leaves-nothing",
                                ("PF", "position", set(), {"*S", "C", "*E", "*E-refused"},
                                 0, 0)),
    "7.packet.bad-checksum-member": ("7.packet.bad-checksum-member.corrupted-end",
                                     ("*E", "silence", {"bad-checksum", "in-packet"},
                                      {"*S", "C"}, None, 4)),
    "7.packet.breakers": ("7.packet.halt-inside",
                          ("@", "silence", {"in-packet"}, {"*S", "C"}, 0, None)),
    # a failed packet's code or count: *S, V10, C-300,0,0,0, *E1 → 3,0 (reference 2,2)
    "7.packet.codes": ("7.packet.invalid-member",
                       ("*E", "code", {"in-packet"}, {"*S", "V", "C"}, 2, 3)),
    "7.packet.exchange": ("7.packet.commits-all",
                          ("*E", "data", {"in-packet"}, {"*S", "B", "C"}, 0, 0)),
    # a packet a watchdog closed by time: *E answered 2,k on its own
    "7.packet.open-until-end": ("7.packet.bad-checksum-member.corrupted-end",
                                ("*E", "code", {"in-packet"}, {"*S", "C"}, 0, 2)),
    # a third party's own placement of the same steps, H and G taken at its next step
    "10.2.motion.step-placement": ("10.4.measured.go-from-rest",
                                   ("PF", "position", {"placement"}, {"L", "H", "G"}, 0, 0)),
    # an A the reference takes, refused as out of range
    "10.cmd.accel-range": ("1.profile.parameter-ranges", ("A", "code", set(), set(), 0, 5)),
    "8.index.counts": ("8.index.counts-every-frame", ("@", "data", set(), {"V"}, 0, 0)),
    # the index written in hex, read so the reference's
    "8.index.decimal": ("10.commands.formats", ("@", "data", {"index-hex"}, {"V"}, 0, 0)),
    # short by the frames refused since the base: what the unit took counted
    # W with a comma after the axis refused as a syntax error: the example's form only
    "10.cmd.reference-syntax": ("10.cmd.reference.to-switch",
                                ("W", "code", set(), set(), 0, 4)),
    "8.index.refused-counted": ("8.index.counts-every-frame",
                                ("@", "data", {"refused-uncounted"}, {"T-refused"}, 0, 0)),
    # a command the spindle's address lacks whose letters begin one it has: 4, not 3
    "1.profile.command-prefix": ("10.commands.absent-refused",
                                 ("VL", "code", {"to-spindle"}, set(), 3, 4, "GVE114")),
    # a C from rest, read within the T after the vector before it ended
    "10.2.motion.dwell-before-c": ("10.2.measured.dwell-before-c",
                                   ("PF", "position", {"in-dwell", "c-from-rest"}, {"C"},
                                    0, 0)),
    # J answered with the INTA bit H left, before its reset
    "10.cmd.restart": ("2.link.restart", ("J", "inta", set(), {"H"}, 0, 0)),
    "8.index.queries-uncounted": ("8.index.queries-not-counted",
                                  ("@", "data", {"queries-counted"}, {"@"}, 0, 0)),
    "8.repeat.answer": ("8.repeat.last-frame-and-answer", (">", "data", set(), {"T"}, 0, 0)),
    "8.repeat.no-reexecute": ("8.repeat.not-reexecuted",
                              ("PF", "position", set(), {"L", ">"}, 0, 0)),
    "8.repeat.remembered": ("8.repeat.queries-forgotten",
                            (">", "data", set(), {"V", "@"}, 0, 0)),
    # vectors refused while the MPG holds RUN, its parameters never set
    "9.reset.mpg-parameters": ("9.reset.mpg-enabled",
                               ("L", "code", {"mpg-on"}, {"EW", "J"}, 7, 0, "GVE114")),
    # Y& refused while an L runs
    "10.cmd.mpg-while-moving": ("10.cmd.mpg.while-moving", ("Y", "code", set(), {"L"}, 0, 7)),
    # a Y& sent with EEPROM 06 as shipped: inert (RUN = 0)
    "9.reset.mpg-inert": ("9.reset.mpg-inert.as-shipped",
                          ("SR", "data", {"mpg-disabled"}, {"Y"}, 0, 0)),
    # a co-simulator's power-on that left the checksum mode on: its first answer summed
    "9.reset.state": ("9.reset.after-j", ("SR", "data", {"summing-after-power-on"}, set(),
                                          0, 0)),
    # a vector refused 7 after an EEPROM 06 value the manual does not list as enabling
    "9.reset.mpg": ("9.reset.mpg-enabled", ("L", "code", set(), {"EW", "Y"}, 0, 7, "GVE114")),
    # RUN read right after a vector alone: the unit did not run it
    "10.cmd.vector": ("10.cmd.positions.each-axis", ("SR", "data", set(), {"L"}, 0, 0)),
    # what the rig sees: the outputs an O set, the spindle !7V set, the axes after N
    "10.cmd.output": ("10.cmd.output.port", ("state:outputs", "data", set(), {"O"}, 0, 0)),
    "12.spindle.speed": ("12.spindle.range-ends",
                         ("state:spindle", "data", set(), {"spindle"}, 0, 0)),
    "10.cmd.zero": ("10.commands.zero-axis",
                    ("state:physical", "position", set(), {"L", "N"}, 0, 0)),
    # a command the spindle's address serves, refused there
    "12.spindle.commands": ("12.spindle.address-7",
                            ("ER", "code", {"to-spindle"}, set(), 0, 3, "GVE114")),
    # W answered before its run ended
    "10.cmd.reference": ("10.cmd.reference.answers-after-travel",
                         ("W", "timing", set(), set(), 0, 0)),
    # where the axis stands after a W that found no switch (answered 5)
    "10.cmd.reference-fails": ("10.cmd.reference.answers-after-travel",
                               ("PF", "position", set(), {"W", "W-refused"}, 0, 0)),
}


def _shared_rules() -> set[str]:
    from conformance.run.selection import select
    graded = {r for c in select() for r in c.rules}
    return {entry.rule for entry in load_labels()} & graded


def test_every_rule_both_use_has_its_behaviour_here():
    assert set(PAIRS) == _shared_rules()


@pytest.mark.parametrize("rule", sorted(PAIRS))
def test_diff_names_the_rule_the_catalogue_grades_the_behaviour_by(rule):
    import conformance.run.selection  # noqa: F401  (registers the cases)
    from conformance.case.context import REGISTRY
    case_id, facts = PAIRS[rule]
    assert rule in REGISTRY[case_id].rules
    command, kind, context, earlier, reference, target, *family = facts
    assert label(command, kind, context, earlier, reference, target, *family) == rule
