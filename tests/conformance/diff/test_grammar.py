"""The grammar draws only what the profile has and the run allows."""

from hypothesis import given, settings
from hypothesis import strategies as st

from conformance.diff.grammar import Grammar, Options, command_names, sequences
from conformance.diff.labels import command_of
from conformance.diff.steps import FILL, FRAME, INPUT
from gve_fixtures.profile import load_profile

GVE54 = load_profile("GVE54")
GVE84 = load_profile("GVE84-100")


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


def test_an_idiom_vector_gets_the_profile_axes():
    assert Grammar(GVE84, Options())._padded("C100") == "C100,0,0"
    assert Grammar(GVE54, Options())._padded("L-5") == "L-5" + ",0" * (len(GVE54.axes) - 1)
    assert Grammar(GVE84, Options())._padded("C1,2,3") == "C1,2,3"


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


def test_an_event_repeat_is_read_whole():
    g = Grammar(GVE84, Options())
    assert g.fixed(">").lines == 2 and g.fixed("H").lines == 1
    assert not g.fixed("*S").answer


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
