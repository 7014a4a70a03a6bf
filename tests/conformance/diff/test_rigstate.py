"""What the rig sees, as answers to compare: only what both rigs give readably, within
bounds (a rig is a target's: nothing it sends is trusted)."""

from __future__ import annotations

from conformance.diff.rigstate import observed


def test_each_key_both_rigs_give_is_an_answer_of_its_own():
    a = {"outputs": "FE", "spindle": 500, "physical": [1, -2, 3]}
    b = {"outputs": "FF", "spindle": "500", "physical": [1, -2, 3]}
    assert list(observed(a, b)) == [
        ("state:outputs", "state", b"0,FE\r", b"0,FF\r"),
        ("state:spindle", "state", b"0,500\r", b"0,500\r"),
        ("state:physical", "PF", b"0,1,-2,3\r", b"0,1,-2,3\r"),
    ]


def test_what_a_rig_does_not_give_readably_is_not_compared():
    good = {"outputs": "FF", "spindle": 0, "physical": [0, 0, 0]}
    for bad in ({}, {"outputs": True, "spindle": None, "physical": "0,0,0"},
                {"outputs": "1FF", "spindle": "-5", "physical": [0, True, 0]},
                {"outputs": "zz", "spindle": "1e3", "physical": [2**70, 0, 0]},
                {"outputs": "FF\r\n", "spindle": [], "physical": []}):
        assert list(observed(bad, good)) == [], bad
        assert list(observed(good, bad)) == [], bad
