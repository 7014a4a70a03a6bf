"""The grammar draws only what the profile has and the run allows."""

from hypothesis import given, settings
from hypothesis import strategies as st

from conformance.diff.grammar import Options, command_names, sequences
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
