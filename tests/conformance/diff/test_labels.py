"""Labels name rules that exist and pick the most specific one."""

from conformance.diff.labels import command_of, label, load_labels, verdict_of
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
