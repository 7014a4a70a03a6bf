"""The halt in the final deceleration books its waits as what they wait for: the longest
dwell T over (the manual's) and the vector under way (motion), none as the suite's own."""

from __future__ import annotations

import pytest

from conformance.link.account import Spent
from conformance.run.runner import run
from conformance.run.selection import select
from conformance.targets import parse_target
from conformance.verdicts.verdict import PASS


def test_the_halt_in_the_final_deceleration_waits_for_the_dwell_and_the_motion():
    result = run([parse_target("emu:GVE84-100")], select(["10.4.halt.in-final-deceleration"]))
    assert [r.verdict for r in result.results] == [PASS]
    (totals,) = [s["time"] for s in result.sessions.values()]
    assert totals[str(Spent.MANUAL)] == pytest.approx(0.03)
    assert totals[str(Spent.MOTION)] >= 0.2
    assert totals[str(Spent.WAITS)] == 0
