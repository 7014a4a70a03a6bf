"""A junction's timing is graded by the rule's own text: the manual fixes B at a junction
of two C going on (10.2.motion.junction [M]) and says nothing of a C that reverses an
axis, where braking to 0 is as defensible (10.2.motion.junction-reversal [D]). diff
against a unit that brakes to rest at reversals finds nothing to FAIL; the motion
mutants still FAIL through it."""

from __future__ import annotations

import pytest

from conformance.diff.engine import Budget, Pair, search
from conformance.diff.grammar import Options, probes
from conformance.diff.sides import Side
from conformance.targets import parse_target
from conformance.verdicts.verdict import FAIL, NON_STRICT

READING = "reversal-brakes-to-rest"


def _findings(spec: str, profile: str) -> list:
    target = parse_target(spec, allow_destructive=True)
    reference = parse_target(f"emu:{profile}")
    options = Options(destructive=True, rig=True)
    budget = Budget(examples=len(probes(target.profile, options)) + 20)
    return [f.disagreement for f in search(Pair(Side(target), Side(reference),
                                                target.profile), options, budget, seed=0)]


@pytest.mark.parametrize("profile", ["GVE84-100", "GVE54", "GVE114-500"])
def test_braking_to_rest_at_a_reversal_is_graded_by_the_reversal_s_reading(profile: str):
    found = _findings(f"emu:{profile}?reading={READING}", profile)
    assert found, "the probes meet a reversal"
    assert {(d.rule, d.verdict) for d in found} == {
        ("10.2.motion.junction-reversal", NON_STRICT)}


@pytest.mark.parametrize("mutant", ["junction-stops", "junction-brake-ignored",
                                    "velocity-ignored", "halt-without-ramp"])
def test_a_motion_mutant_still_fails_through_the_reading(mutant: str):
    found = _findings(f"emu:GVE84-100?reading={READING}&mutant={mutant}", "GVE84-100")
    assert any(d.verdict == FAIL and d.tag in ("M", "M-ex") for d in found), \
        [(d.rule, d.verdict) for d in found]
