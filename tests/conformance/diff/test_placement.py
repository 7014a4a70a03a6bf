"""diff against somebody else's unit in virtual time compares positions and an H's
instant as the measured cases judge them (conformance/motion/tolerance.py): a step of
placement, a step period of rest; against the reference's own kind (--strict) exactly.
The reading steps-a-period-late counts its steps a step period late."""

from __future__ import annotations

import pytest

from conformance.diff.engine import Budget, Pair, search
from conformance.diff.grammar import Options, probes
from conformance.diff.sides import Side
from conformance.targets import parse_target
from conformance.verdicts.verdict import FAIL

READING = "steps-a-period-late"


def _findings(spec: str, profile: str, *, strict: bool = False) -> list:
    target = parse_target(spec, allow_destructive=True, strict=strict)
    reference = parse_target(f"emu:{profile}")
    options = Options(destructive=True, rig=True)
    budget = Budget(examples=len(probes(target.profile, options)) + 20)
    return [f.disagreement for f in search(Pair(Side(target), Side(reference),
                                                target.profile), options, budget, seed=0)]


@pytest.mark.parametrize("profile", ["GVE84-100", "GVE54", "GVE114-500"])
def test_another_placement_makes_no_difference(profile: str) -> None:
    assert _findings(f"emu:{profile}?reading={READING}", profile) == []


def test_the_reference_s_own_kind_is_compared_exactly() -> None:
    found = _findings(f"emu:GVE84-100?reading={READING}", "GVE84-100", strict=True)
    assert {d.kind for d in found} >= {"position", "timing"}
    assert all(d.verdict == FAIL for d in found)


@pytest.mark.parametrize("mutant", ["velocity-ignored", "junction-brake-ignored",
                                    "halt-without-ramp"])
def test_a_motion_mutant_still_fails_through_another_placement(mutant: str) -> None:
    found = _findings(f"emu:GVE84-100?reading={READING}&mutant={mutant}", "GVE84-100")
    assert any(d.verdict == FAIL and d.tag in ("M", "M-ex") for d in found), found
