"""The grammar draws only what the profile has and the run allows."""

from hypothesis import given, settings
from hypothesis import strategies as st

from conformance.diff.grammar import (
    Grammar,
    Options,
    command_names,
    sequences,
    table_values,
    value_frames,
)
from conformance.diff.labels import command_of
from conformance.diff.steps import FILL, FRAME, INPUT
from gve_fixtures.profile import load_profile

GVE54 = load_profile("GVE54")
GVE84 = load_profile("GVE84-100")
GVE114 = load_profile("GVE114-500")


def test_destructive_commands_only_when_allowed():
    safe = command_names(GVE84, Options())
    assert not {"J", "EW", "W"} & set(safe)
    assert {"J", "EW", "W"} <= set(command_names(GVE84, Options(destructive=True)))


def test_commands_the_profile_lacks_are_never_named():
    names = set(command_names(GVE54, Options(destructive=True)))
    assert "M" in names and not {"%", "*S", "*E", "VL", "XM", "W"} & names


@settings(max_examples=60, deadline=None)
@given(st.data())
def test_sequences_stay_inside_the_profile(data):
    steps = data.draw(sequences(GVE54, Options()))
    for s in steps:
        if s.kind in (FRAME, FILL):
            name = command_of(s.body)
            assert name in GVE54.commands or name in ("", "SW6") or name == "O", s
            assert not s.body.upper().startswith(("J", "EW", "%", "*")), s
        assert s.kind != INPUT                       # no rig asked for


def test_idioms_that_show_the_dwell_and_an_eeprom_write_are_drawn():
    everything = Grammar(GVE84, Options(destructive=True)).scenarios
    assert ("EW10,5A", "ER10") in everything
    assert any(s[:2] == ("T24", "A10000") and s.count("C100") >= 2 for s in everything)
    assert ("EW10,5A", "ER10") not in Grammar(GVE84, Options()).scenarios


@settings(max_examples=150, deadline=None)
@given(st.data())
def test_every_repeat_awaits_its_two_lines(data):
    # `>` answers the frame it repeats, then the answer: drawn as an event of a motion or
    # in an idiom too, both lines are read (one line would leave the answer behind and
    # count the repeated frame as a silence of the target)
    steps = data.draw(sequences(GVE84, Options(destructive=True)))
    for s in steps:
        if s.kind == FRAME and command_of(s.body) == ">":
            assert s.lines == 2, s
        if s.kind == FRAME and command_of(s.body) == "*S":
            assert not s.answer, s


@settings(max_examples=200, deadline=None)
@given(st.data())
def test_a_reference_run_lasts_a_fraction_of_a_second(data):
    """W answers when its run has ended: a valid one (each leg at most 300 steps, rates
    in range; the invalid forms are refused at once) runs each leg at 900 steps/s or more,
    or the line would be held for minutes."""
    steps = data.draw(sequences(GVE84, Options(destructive=True)))
    v = GVE84.range("V")
    for s in steps:
        if s.kind == FRAME and s.body.startswith("W"):
            fields = s.body[2:].lstrip(",").split(",")
            if len(fields) != 4 or not all(f.lstrip("-").isdigit() for f in fields):
                continue
            n2, n3, n4, n5 = (int(f) for f in fields)
            if max(abs(n2), abs(n4)) <= 300 and all(v.lo <= n <= v.hi for n in (n3, n5)):
                assert (abs(n2) + abs(n4)) / min(n3, n5) <= 2 / 3, s


def test_a_fields_table_values_are_its_ranges_ends_each_word_and_each_axis():
    feed = GVE84.range("V")
    assert table_values(GVE84, "range:V") == [str(feed.lo), str(feed.hi)]
    assert table_values(GVE84, "dec:0:6") == ["0", "1", "2", "3", "4", "5", "6"]
    assert table_values(GVE84, "hex:0:255") == ["00", "FF"]
    assert table_values(GVE84, "choice:+|-") == ["+", "-"]
    assert table_values(GVE114, "axis") == ["X", "Y", "Z", "A"]
    # drawn otherwise (short moves and travels, a travel's rates, floats): no table
    assert not any(table_values(GVE84, k) for k in ("vector", "travel", "seek-rate", "float"))


def test_each_table_value_is_a_frame_of_its_own_the_other_fields_held():
    frames = value_frames(GVE84, command_names(GVE84, Options(destructive=True)))
    feed = GVE84.range("V")
    assert {f"V{feed.lo}", f"V{feed.hi}", "SR0", "SR6", "ER00", "ERFF"} <= set(frames)
    # one field at a time at each end, the others at their first value
    assert {"EW00,00", "EWFF,00", "EW00,FF"} <= set(frames) and "EWFF,FF" not in frames
    assert len(frames) == len(set(frames))
    # *E's count is diff's own range, no manual's table
    assert not any(f.startswith("*E") for f in frames)


def test_the_tables_move_each_axis_alone_and_ground_several_inputs_at_once():
    tables = Grammar(GVE114, Options(destructive=True, rig=True)).tables
    firsts = {t[0] for t in tables if len(t) > 1}
    # the GVE114's A alone, which no command reads back: run (ST6, F) right after it
    assert ("L0,0,0,100", "SR6", "wait 0.2", "PF", "C0,0,0,100", "F") in tables
    # ST1's two interrupt inputs (I2's bits 6 and 7) enabled and grounded together, the
    # cause word read; and the first of them alone
    assert ("SW1,C0", "input 2 00", "SR5", "input 2 FF", "D") in tables
    assert "SW1,40" in firsts
    # without a rig no input is set: the idioms that need one are left out
    plain = Grammar(GVE114, Options(destructive=True)).tables
    assert not any(line.startswith("input ") for t in plain for line in t)
