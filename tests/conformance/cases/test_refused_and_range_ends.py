"""The cases of every range end and of what a refusal leaves behind catch the mutant made
for each, on every family the case applies to, through the check of the rule it breaks,
and PASS the clean emulator there."""

from __future__ import annotations

import pytest

from conformance.run.runner import run_case
from conformance.run.selection import select
from conformance.targets import parse_target
from tests.conformance.cases.catching import assert_catches

FAMILIES = ("GVE84-100", "GVE114-500", "GVE54")

#: mutant -> (the case made to catch it, the rule of its failing check, the profiles)
CATCHES = {
    "narrow-counters": ("10.commands.counter-range-ends", "10.cmd.positions",
                        ("GVE84-100", "GVE114-500")),
    "eeprom-7-bit-address": ("10.6.eeprom.every-address", "10.cmd.eeprom-bytes", FAMILIES),
    "refused-vector-queued": ("10.1.queue.refused-leaves-queue",
                              "4.response.failed-not-executed", FAMILIES),
    "refused-vector-overwrites": ("10.1.queue.refused-leaves-queue",
                                  "4.response.failed-not-executed", FAMILIES),
    "failed-packet-keeps-b": ("7.packet.failed-leaves-nothing", "7.packet.all-or-nothing",
                              ("GVE84-100", "GVE114-500")),
}


@pytest.mark.parametrize(("mutant", "profile"),
                         [(m, p) for m, (_, _, ps) in CATCHES.items() for p in ps])
def test_the_case_catches_its_mutant(mutant: str, profile: str) -> None:
    case_id, rule, _ = CATCHES[mutant]
    assert_catches(case_id, rule, mutant, profile)


def test_the_counters_case_reaches_both_ends_and_just_beyond() -> None:
    (c,) = select(["10.commands.counter-range-ends"])
    r = run_case(c, parse_target("emu:GVE84-100"), "ci")
    sent = [k["what"] for k in r.checks]
    for frame in ("NX2147483647 → 0", "NY-2147483647 → 0", "NX2147483648 → 5",
                  "NY-2147483648 → 5"):
        assert frame in sent
