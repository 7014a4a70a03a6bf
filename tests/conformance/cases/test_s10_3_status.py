"""Spec 10.3's cases against readings: a unit that reads its inputs as edges is judged by
the level rule's [D] grade, not left untested by the case's setup."""

from __future__ import annotations

from conformance.run.runner import run
from conformance.run.selection import select
from conformance.targets import parse_target
from conformance.verdicts.verdict import NON_STRICT


def test_enabling_an_active_input_that_does_not_interrupt_is_the_level_rule_s_non_strict():
    result = run([parse_target("emu:GVE84-100?reading=edge-triggered-inputs")],
                 select(["10.3.inputs.level-after-clearing"]))
    (r,) = result.results
    assert r.verdict == NON_STRICT, (r.verdict, r.notes)
    assert {c["rule"] for c in r.checks if not c["ok"]} == {"10.3.inputs.level-triggered"}
