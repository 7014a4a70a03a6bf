"""A host's frame judged against spec 3, 6 and 10: each problem names its rule. The
expected rules and frames come from the spec's own examples."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from conformance.host.frame_rules import command_of, parse_frame
from gve_fixtures.profile import load_profile

GVE84 = {0: load_profile("GVE84-100")}
GVE54 = {0: load_profile("GVE54")}
GVE114 = {0: load_profile("GVE114-500"), 7: load_profile("GVE114-500")}


def rules(raw: bytes, units=GVE84, checksums: bool = False) -> list[str]:
    return [p.rule for p in parse_frame(raw, units, checksums).problems]


@pytest.mark.parametrize("raw", [
    b"!0V1000", b"!0L1000,0,0", b"!0C-1000,20,0", b"!0SW1,3F", b"!0SR2", b"!0PF", b"!0?",
    b"!0VL25000,25000,30000", b"!0WY,-20000,1000,2000,500", b"!0WY-20000,1000,2000,500",
    b"!0O0,FB", b"!0EW01,00", b"!0NX100", b"!0*S", b"!0*E10", b"!0XM200", b"!0T0000000000005",
    b"!0SW0,001",
])
def test_the_spec_examples_are_well_formed(raw):
    assert rules(raw) == []


def test_checksums_as_spec_6_sums_them():
    assert rules(b"!0A100,4F", checksums=True) == []           # spec 6, G2
    assert rules(b"!0A100,4E", checksums=True) == ["6.checksum.sum"]
    assert rules(b"!0A100", checksums=True) == ["6.checksum.sum"]   # missing
    # a read left unsummed is refused with nothing run: a probe of the mode, a decision
    assert rules(b"!0F", checksums=True) == ["6.checksum.unsummed-query"]
    assert rules(b"!0V1000", checksums=True) == ["6.checksum.sum"]   # a setting
    assert rules(b"!0%-,CF", checksums=True) == []             # spec 6, G1


@pytest.mark.parametrize(("raw", "rule"), [
    (b"!0l1000,0,0", "3.frame.upper-case"),                     # spec 3: `!0l…` → 3
    (b"!0?5", "3.params.none-expected"),                        # spec 3: `!0?5` → 4
    (b"!0@1", "3.params.none-expected"),
    (b"!0V20000.0", "3.params.decimal"),                        # a non-digit → 4
    (b"!0V+5", "3.params.decimal"),                             # a `+` → 4
    (b"!0L100,,0", "3.params.decimal"),                         # an empty field → 4
    (b"!0L100 0 0", "3.params.commas"),                         # spec 3: commas
    (b"!0L1,2,3,4", "1.profile.axes"),                          # three axes on the GVE84
    (b"!0L1,2", "10.cmd.vector"),
    (b"!0SW8,F1", "5.code.range"),                              # spec 5 / G4: → 5
    (b"!0SW2,FFF", "5.code.range"),                             # spec 3: → 5
    (b"!0SW1,XY", "3.params.hex-fields"),
    (b"!0L9999999999999,0,0", "1.profile.vector-range"),        # spec 3: → 5
    (b"!0V200000", "1.profile.v-b-range"),                      # above the variant's max
    (b"!0A0", "10.cmd.accel-range"),
    (b"!0T25", "10.cmd.modal"),
    (b"!0VL5,100,100", "10.cmd.axis-limits"),
    (b"!1V1000", "2.link.addressed-only"),                      # no unit at address 1
    (b"!9V1000", "3.frame.grammar"),                            # no address 0..7
    (b"!0ZZ", "1.profile.command-set"),
    (b"!0M4", "1.profile.command-set"),                         # M is the GVE54's
    (b"!0" + b"T" + b"0" * 93 + b"5", "3.frame.max-length"),   # 97 bytes
])
def test_each_problem_names_its_rule(raw, rule):
    assert rule in rules(raw)


def test_family_rules():
    assert rules(b"!0*S", GVE54) == ["1.profile.gve54-no-checksums"]   # spec 1
    assert rules(b"!0V30", GVE54) == ["1.profile.v-b-range-gve54"]      # M54: 40..50000
    assert rules(b"!0L65536,0,0", GVE54) == ["1.profile.vector-range"]  # ±65535
    assert rules(b"!0MF", GVE54) == []
    assert rules(b"!0L1,2,3,4", GVE114) == []                           # 3 or 4 values
    assert rules(b"!0EFW10,1e+3", GVE114) == []                         # spec 3
    assert rules(b"!0EFW10,+1", GVE114) == ["3.params.float-syntax"]
    assert rules(b"!0EUW10,FF", GVE114) == ["3.params.word-values-decimal"]


def test_the_spindle_address():
    assert rules(b"!7V300", GVE114) == []                               # spec 12, G8
    assert rules(b"!7V1001", GVE114) == ["12.spindle.speed"]
    assert rules(b"!7L1,0,0", GVE114) == ["1.profile.command-set"]      # spec 12: → 3


def test_every_judged_frame_names_the_rules_it_was_held_to():
    f = parse_frame(b"!0V1000,C4", GVE84, True)
    assert {"3.frame.grammar", "6.checksum.sum", "1.profile.v-b-range"} <= f.judged
    assert f.command == "V" and f.params == ["1000"] and f.checksum == "C4"


@pytest.mark.parametrize("raw", [
    b"!0H", b"!0H,5A", b"!0W", b"!0WY,-20000,1000,2000,500", b"!0>", b"!0>,6E", b"!0N",
    b"!0N,4E", b"!0NX100", b"!0NX100,12", b"!0XA", b"!0XA,AA", b"!0EFW1,2.5", b"!0*E3",
    b"!0*E3,C2", b"!0h", b"!0?", b"!0,41", b"!0", b"!", b"!9V1000", b"!3V1000", b"!0ZZ",
    b"!0V\xff", b"!7V1000", b"!7V1000,8E",
])
@pytest.mark.parametrize("checksums", [False, True])
@pytest.mark.parametrize("units", [GVE84, GVE114, GVE54], ids=["GVE84", "GVE114", "GVE54"])
def test_the_relays_command_is_the_judges(raw, checksums, units):
    """The relay reads only the command while a frame is on the line; the judge reads
    the whole frame later, in the checksum mode of its unit: both find the same command."""
    assert command_of(raw, units) == parse_frame(raw, units, checksums).command


@given(st.binary(max_size=12).map(lambda b: b"!0" + b)
       | st.text("!0123456789HWNXAVLC*SE>?@,%+-", max_size=10).map(lambda s: s.encode()),
       st.booleans())
def test_the_relays_command_is_the_judges_for_any_bytes(raw, checksums):
    assert command_of(raw, GVE114) == parse_frame(raw, GVE114, checksums).command


def test_a_frame_is_classed_as_every_reader_classes_it_and_judged_strictly():
    lower = parse_frame(b"!0sw6,00", GVE84, False)
    assert (lower.command, lower.key) == (None, "SW6")      # the unit takes no command
    assert [p.rule for p in lower.problems] == ["3.frame.upper-case"]
    plus = parse_frame(b"!0SW+6,00", GVE84, False)
    assert (plus.command, plus.key) == ("SW", "SW6")
    assert [p.rule for p in plus.problems] == ["3.params.decimal"]
    assert parse_frame(b"!0SW0,80", GVE84, False).key == "SW"
    assert command_of(b"!0H", GVE84) == "H" and command_of(b"!0h", GVE84) is None


@pytest.mark.parametrize("raw", [b"!0L" + b"1" * 5000 + b",0,0", b"!0SW1," + b"F" * 5000,
                                 b"!0L\x1b]0;x\x07,0,0"])
def test_a_host_s_hostile_field_is_a_problem_of_its_frame_shown_escaped(raw):
    """More digits than int() reads, or an escape sequence: a problem named by its rule,
    never a crash, never a raw control byte in what a report shows."""
    problems = parse_frame(raw, GVE84, False).problems
    assert problems and all(p.rule for p in problems)
    assert not any(ch in p.what for p in problems for ch in "\x1b\x07")


def test_a_frame_summed_after_a_restart_turned_the_mode_off_names_that_cause():
    from conformance.host.frame_rules import LineRules
    line = LineRules(GVE84)
    f = line.parse(b"!0@,BD", False, lapsed=True)
    assert [p.rule for p in f.problems] == ["6.checksum.off-after-reset"]
    assert f.command == "@" and not f.params
    # without a restart behind it the same frame is read as the unit reads it
    assert "3.params.none-expected" in rules(b"!0@,BD")
    # a last field that is no sum of the frame is a parameter still
    assert "6.checksum.off-after-reset" not in [
        p.rule for p in line.parse(b"!0SW2,00", False, lapsed=True).problems]
