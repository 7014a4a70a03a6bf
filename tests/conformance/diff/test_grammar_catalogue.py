"""diff draws the catalogue's commands: each under the name a profile's command set uses,
with the catalogue's parameters unless grammar.toml's [draw] says otherwise."""

from __future__ import annotations

from conformance.diff.grammar import load_grammar
from conformance.protocol.catalogue import commands


def test_every_command_is_drawn_by_its_profile_name_in_spec_order():
    assert list(load_grammar()["command"]) == [c.known_as for c in commands().values()]


def test_parameters_come_from_the_catalogue():
    g = load_grammar()["command"]
    assert g["SW"]["params"] == ["dec:0:6", "hex:0:255"]
    assert g["O0"] == {"text": "O", "params": ["dec:0:0", "hex:0:255"]}
    assert g["L"]["params"] == ["vector"] and g["VL"]["params"] == ["range:VL"] * 3
    assert g["M"]["params"] == ["choice:U|D|2|4|8|F"]
    assert g["EUW"]["params"] == ["hex:0:252", "dec:0:4294967295"]


def test_draw_overrides_and_answers():
    g = load_grammar()["command"]
    assert g["W"]["params"][0] == "axis" and g["W"]["destructive"]
    assert g["*E"]["params"] == ["dec:0:4"]
    assert g["J"] == {"destructive": True, "then_wait": "restart"}
    assert g["*S"] == {"answer": False}
    assert g[">"] == {"lines": 2, "weight": 2}
    assert g["PF"] == {"weight": 6}
