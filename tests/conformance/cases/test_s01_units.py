"""Spec section 1's cases against readings: where the manuals allow a unit two answers,
the case's own setup takes either and still judges."""

from __future__ import annotations

from conformance.run.runner import run
from conformance.run.selection import select
from conformance.targets import parse_target
from conformance.verdicts.verdict import PASS


def test_the_axis_count_is_judged_on_a_unit_whose_g_with_nothing_queued_answers_6():
    # on a GVE54 both vectors are refused, so nothing is queued for the G that follows
    result = run([parse_target("emu:GVE54?reading=go-clears-then-nothing")],
                 select(["1.profile.axes.count"]))
    (r,) = result.results
    assert r.verdict == PASS, (r.verdict, r.notes)
    assert any(c["rule"] == "1.profile.axes" for c in r.checks)
