"""A form the manuals leave open is graded once, by its own [D] rule, in its own case:
the index written in hex, refused frames left out of the index, a lacking command read
as one the unit has with parameters it does not take. No other case changes its
verdict."""

from __future__ import annotations

import pytest

from conformance.run.runner import run_case
from conformance.run.selection import select
from conformance.targets import parse_target
from conformance.verdicts.verdict import NON_STRICT

#: reading -> the case that grades it, the rule
GRADED = {
    "index-hex": ("10.commands.formats", "8.index.decimal"),
    "absent-command-syntax": ("10.commands.absent-refused", "1.profile.command-prefix"),
    "refused-uncounted": ("8.index.counts-every-frame", "8.index.refused-counted"),
}
#: the cases that read the index, or send commands the GVE54 lacks, besides
NEIGHBOURS = ["8.*", "9.reset.after-j", "6.checksum.*", "7.packet.breakers",
              "3.frame.*", "10.commands.*", "5.machine.error-codes",
              "10.machine.queue-status-eeprom"]


@pytest.mark.parametrize("reading", sorted(GRADED))
def test_the_reading_is_graded_once_by_its_rule(reading: str) -> None:
    case_id, rule = GRADED[reading]
    clean, read = parse_target("emu:GVE54"), parse_target(f"emu:GVE54?reading={reading}")
    for c in select(NEIGHBOURS):
        before, after = run_case(c, clean, "ci"), run_case(c, read, "ci")
        if c.id != case_id:
            assert after.verdict == before.verdict, (c.id, after.checks)
            continue
        failed = [k for k in after.checks if not k["ok"]]
        assert after.verdict == NON_STRICT and failed
        assert {k["rule"] for k in failed} == {rule}
