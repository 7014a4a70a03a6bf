"""Exact only where exactness is ours (conformance/motion/tolerance.py): the model's step
placement and rounding are the project's reading of manuals that give rates and ramps,
not rounding. Against the reference emulator, or a target run with --strict, a measured
check is exact; against somebody else's unit in virtual time (a co-simulator) it allows
a step of placement on each axis and an H that comes to rest a step period either side.
The reading steps-a-period-late is such a unit: its counters show each step a step
period after the suite's arithmetic places it, and its H answers a step period late."""

from __future__ import annotations

import pytest

from conformance.case.context import REGISTRY
from conformance.cli.mutation import FIRST
from conformance.run.runner import run_case
from conformance.run.selection import select
from conformance.targets import emu, parse_target
from conformance.verdicts.verdict import ERROR, FAIL, NON_STRICT, PASS
from emulator.mutants import CORE_DEVIATIONS

READING = "steps-a-period-late"
MEASURED = [c for c in select() if ".measured." in c.id]
#: the mutants of the motion: the stepper core's, and those of spec 10.2 and 10.4
MOTION = sorted({*CORE_DEVIATIONS, *(name for name, (area, _) in emu.mutants().items()
                                     if area in ("10.2", "10.4"))})


@pytest.mark.parametrize("profile", FIRST)
def test_another_placement_passes_every_measured_case_in_virtual_time(profile: str) -> None:
    target = parse_target(f"emu:{profile}?reading={READING}")
    verdicts = {c.id: run_case(c, target, "mutation").verdict for c in MEASURED}
    assert {v for v in verdicts.values()} <= {PASS, "MISSING"}, verdicts


def test_the_reference_and_a_strict_target_stay_exact() -> None:
    case = REGISTRY["10.2.measured.cruise-at-v"]
    strict = parse_target(f"emu:GVE84-100?reading={READING}", strict=True)
    r = run_case(case, strict, "mutation")
    assert r.verdict == FAIL
    assert all(c["expected"].count("..") == 0 for c in r.checks if "PF at" in c["what"])
    assert run_case(case, parse_target("emu:GVE84-100"), "mutation").verdict == PASS


def test_the_band_a_third_party_gets_is_printed() -> None:
    r = run_case(REGISTRY["10.4.measured.halt-ramp"],
                 parse_target(f"emu:GVE84-100?reading={READING}"), "mutation")
    assert r.verdict == PASS
    assert any("±1 step" in c["what"] for c in r.checks)
    assert any("H answered" in c["what"] and " ms)" in c["what"] for c in r.checks)


@pytest.mark.parametrize("mutant", MOTION)
def test_a_motion_mutant_still_fails_through_another_placement(mutant: str) -> None:
    # the measured cases and those of the mutant's area, as somebody else's unit: a bug
    # off by more than a step FAILs by its [M] rule; one of a decided rule is NON-STRICT
    area = emu.mutants()[mutant][0]
    cases = MEASURED + [c for c in select() if c.section == area and c not in MEASURED]
    seen = []
    for profile in FIRST:
        third = parse_target(f"emu:{profile}?reading={READING}&mutant={mutant}")
        ours = parse_target(f"emu:{profile}?mutant={mutant}")
        for c in cases:
            r = run_case(c, third, "mutation")
            assert r.verdict != ERROR, (c.id, r.notes)
            if r.verdict == FAIL:
                return
            caught = run_case(c, ours, "mutation")
            if caught.verdict == FAIL:
                tags = {ch["tag"] for ch in caught.checks if not ch["ok"]}
                seen.append((c.id, profile, r.verdict, tags))
    assert seen and all(verdict == NON_STRICT and tags == {"D"}
                        for _, _, verdict, tags in seen), seen


def test_a_along_the_path_under_vk_is_graded_by_its_own_rule_and_vk_ignored_still_fails():
    """A unit taking A along |d| under VK (reading accel-along-path: M84 12.5.4 puts the
    speeds along |d| and says nothing of A) runs path-rate's scenario behind the model's,
    whose dominant axis ramps at A; with A taken as one byte (accel-byte-range: A10000
    refused, the scenario measured at the reset's A20) the ramps show: every reading it
    misses is graded by 10.2.motion.path-accel [D], as the whole scenario is the model's
    with A along the path; VK ignored is faster, not slower, and still FAILs the path rate
    [M] through it."""
    case = REGISTRY["10.2.measured.path-rate"]
    readings = "emu:GVE84-100?reading=accel-along-path,accel-byte-range"
    r = run_case(case, parse_target(readings), "mutation")
    assert r.verdict == NON_STRICT
    assert {c["rule"] for c in r.checks if not c["ok"]} == {"10.2.motion.path-accel"}
    assert run_case(case, parse_target(readings, strict=True), "mutation").verdict == FAIL
    ignored = parse_target(f"{readings}&mutant=path-speed-ignored")
    r = run_case(case, ignored, "mutation")
    assert r.verdict == FAIL
    assert "10.2.motion.path-rate" in {c["rule"] for c in r.checks if not c["ok"]}
