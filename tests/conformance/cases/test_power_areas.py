"""The cases of the areas the catalogue used to sample (which B governs a junction,
settings that share nothing, each micro-step mode, what a refusal leaves read back)
catch the mutant made for each on every profile the case applies to, through the check
of the rule it breaks, PASS the clean emulator there, and grade the reading of a silence
NON-STRICT, never FAIL."""

from __future__ import annotations

import pytest

from conformance.run.runner import run_case
from conformance.run.selection import select
from conformance.targets import parse_target
from conformance.verdicts.verdict import FAIL, NON_STRICT, PASS
from tests.conformance.cases.catching import assert_catches

#: mutant -> (the case made to catch it, the rule of its failing check, the profiles)
CATCHES = {
    "junction-brake-ignored": ("10.2.measured.junction-brake-sides", "10.2.motion.junction",
                               ("GVE84-100", "GVE114-500", "GVE54")),
    "spindle-sets-feed-rate": ("12.spindle.measured.feed-unchanged",
                               "12.spindle.feed-independent", ("GVE114-500",)),
    "axis-limit-x-for-all": ("10.cmd.measured.axis-limits-own-axis",
                             "10.cmd.axis-limits-own-axis", ("GVE84-100", "GVE114-500")),
    "override-rewrites-velocity": ("10.cmd.measured.override-leaves-v",
                                   "10.cmd.override-leaves-v", ("GVE84-100", "GVE114-500")),
    "microstep-modes-swapped": ("10.7.microstep.each-mode", "10.7.motor.modes", ("GVE54",)),
    "refused-status-write-stored": ("4.machine.refusals-read-back",
                                    "4.response.failed-not-executed", ("GVE84-100",)),
    "velocity-refused-stored": ("4.machine.refusals-read-back",
                                "4.response.failed-not-executed",
                                ("GVE84-100", "GVE114-500", "GVE54")),
    "accel-refused-stored": ("4.machine.refusals-read-back",
                             "4.response.failed-not-executed",
                             ("GVE84-100", "GVE114-500", "GVE54")),
    "failed-packet-applies-v": ("4.machine.refusals-read-back", "7.packet.all-or-nothing",
                                ("GVE84-100", "GVE114-500")),
    "velocity-syntax-refused-stored": ("4.machine.refusals-read-back",
                                       "4.response.failed-not-executed",
                                       ("GVE84-100", "GVE114-500", "GVE54")),
    "brake-refused-stored": ("4.machine.refusals-read-back",
                             "4.response.failed-not-executed",
                             ("GVE84-100", "GVE114-500", "GVE54")),
    "dwell-refused-stored": ("4.machine.refusals-read-back",
                             "4.response.failed-not-executed",
                             ("GVE84-100", "GVE114-500", "GVE54")),
    "microstep-refused-stored": ("4.machine.refusals-read-back",
                                 "4.response.failed-not-executed", ("GVE54",)),
    "spindle-refused-stored": ("4.machine.refusals-read-back",
                               "4.response.failed-not-executed", ("GVE114-500",)),
    "failed-packet-keeps-b": ("4.machine.refusals-read-back", "7.packet.all-or-nothing",
                              ("GVE84-100", "GVE114-500")),
    "refused-line-queued": ("4.machine.refusals-read-back",
                            "4.response.failed-not-executed",
                            ("GVE84-100", "GVE114-500", "GVE54")),
    "input-bits-swapped": ("10.cmd.ports.bit-by-bit", "10.cmd.port-bits",
                           ("GVE84-100", "GVE114-500", "GVE54")),
    # every value of a table, both ends of a range, a mode with every command on it
    "mpg-enable-high-values-ignored": ("9.reset.mpg-enabling-values", "9.reset.mpg",
                                       ("GVE114-500", "GVE114-50")),
    "spindle-low-end-off": ("12.spindle.range-ends", "12.spindle.speed", ("GVE114-500",)),
    "slow-rates-floored": ("10.2.measured.range-ends", "10.2.motion.dominant-rate",
                           ("GVE84-100", "GVE114-500", "GVE54")),
    "microstep-continuous-unscaled": ("10.7.microstep.with-motion-commands",
                                      "10.7.motor.modes", ("GVE54",)),
    # an axis alone, read where the protocol reads it and where the rig does
    "a-axis-alone-ignored": ("10.cmd.positions.each-axis", "10.cmd.vector", ("GVE114-500",)),
    # several interrupt sources at once
    "cause-lowest-only": ("10.3.interrupt.several-at-once", "10.3.status.meaning",
                          ("GVE84-100", "GVE114-500", "GVE54")),
    "cause-includes-disabled": ("10.3.interrupt.several-at-once", "10.3.status.meaning",
                                ("GVE84-100", "GVE114-500", "GVE54")),
    # an answer's instant by the unit's own time, flags and counters (no rig)
    "reference-answers-early": ("10.cmd.reference.answers-after-travel", "10.cmd.reference",
                                ("GVE84-100", "GVE114-500")),
}

#: further cases made for a mutant: (case, mutant, the rule of its failing check, profile)
ALSO = (
    ("10.3.status.register-ends", "refused-status-write-stored", "10.cmd.status-words",
     "GVE54"),
    ("10.cmd.vector.every-axis-on-the-rig", "a-axis-alone-ignored", "10.cmd.vector",
     "GVE114-500"),
    ("10.cmd.reference.inputs", "reference-answers-early", "10.cmd.reference", "GVE84-100"),
    ("10.cmd.reference.to-switch", "reference-answers-early", "10.cmd.reference",
     "GVE114-500"),
)

#: the rule a third party's own placement of the same steps is graded by
PLACEMENT = "10.2.motion.step-placement"
#: reading -> (the case that measures its point, the rule it reads, the profiles)
READ = {
    "next-vectors-B": ("10.2.measured.junction-brake-sides", "10.2.motion.junction-own-b",
                       ("GVE84-100", "GVE54")),
    "cause-first-only": ("10.3.interrupt.several-at-once", "10.3.inputs.cause-accumulates",
                         ("GVE84-100", "GVE114-500", "GVE54")),
}


@pytest.mark.parametrize(("mutant", "profile"),
                         [(m, p) for m, (_, _, ps) in CATCHES.items() for p in ps])
def test_the_case_catches_its_mutant(mutant: str, profile: str) -> None:
    case_id, rule, _ = CATCHES[mutant]
    assert_catches(case_id, rule, mutant, profile, only=False)


@pytest.mark.parametrize(("reading", "profile"),
                         [(r, p) for r, (_, _, ps) in READ.items() for p in ps])
def test_the_reading_grades_non_strict(reading: str, profile: str) -> None:
    case_id, rule, _ = READ[reading]
    (c,) = select([case_id])
    read = run_case(c, parse_target(f"emu:{profile}?reading={reading}"), "mutation")
    assert read.verdict == NON_STRICT
    # (a reading the model with another step placement also explains is graded by that
    # placement's [D] rule beside its own: both NON-STRICT, neither a FAIL)
    assert {k["rule"] for k in read.checks if not k["ok"]} - {PLACEMENT} == {rule}


def test_the_spindle_case_reads_the_spindle_after_each_feed_rate() -> None:
    (c,) = select(["12.spindle.unchanged-by-feed"])
    r = run_case(c, parse_target("emu:GVE114-500"), "ci")
    assert r.verdict == PASS
    assert [k["what"] for k in r.checks if "still at 300" in k["what"]] == [
        f"the spindle still at 300 after !0V{v}" for v in (40, 2000, 1000)]


def test_the_mode_case_moves_in_every_mode_of_the_profile() -> None:
    (c,) = select(["10.7.microstep.each-mode"])
    r = run_case(c, parse_target("emu:GVE54"), "ci")
    assert r.verdict == PASS
    ends = [k["what"] for k in r.checks if k["rule"] == "10.7.motor.modes"]
    for mode, sixteenths in (("2", 8), ("4", 4), ("8", 2), ("F", 1)):
        assert f"M{mode}: L60,-30,15 ends {sixteenths} sixteenths a step on" in ends


@pytest.mark.parametrize(("case_id", "mutant", "rule", "profile"), ALSO)
def test_a_further_case_catches_the_mutant(case_id: str, mutant: str, rule: str,
                                           profile: str) -> None:
    (c,) = select([case_id])
    broken = run_case(c, parse_target(f"emu:{profile}", mutant=mutant), "mutation")
    assert broken.verdict == FAIL
    assert rule in {k["rule"] for k in broken.checks if not k["ok"]}
    assert run_case(c, parse_target(f"emu:{profile}"), "mutation").verdict == PASS
