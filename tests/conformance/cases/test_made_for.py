"""Each case written for an interaction of the spec revision or for a motion parameter
PASSes the emulator and FAILs the mutant of the emulator made for it (that mutant's one
deviation is what the case's rule forbids)."""

from __future__ import annotations

import pytest

from conformance.run.runner import run_case
from conformance.run.selection import select
from conformance.targets import parse_target
from conformance.verdicts.verdict import FAIL, PASS

# case -> (the mutant made for it, the profile it shows on)
MADE_FOR = {
    "10.3.inputs.level-after-clearing": ("inputs-forgotten-after-delete", "GVE84-100"),
    "10.5.restore.save-emptied": ("restore-keeps-save", "GVE84-100"),
    "10.2.measured.zero-length-c": ("zero-c-keeps-junction", "GVE114-500"),
    "10.3.sw6.writing-st6": ("sw6-inert", "GVE84-100"),
    "9.reset.mpg-enabled": ("mpg-not-moving", "GVE114-500"),
    "10.2.measured.no-dwell-continuous": ("dwell-between-continuous", "GVE84-100"),
    "10.3.inputs.physical-across-restart": ("restart-resets-inputs", "GVE84-100"),
    "10.cmd.flags-after-keep.one-vector": ("flags-ignore-keep-capacity", "GVE84-100"),
    "10.4.halt.in-final-deceleration": ("halt-short-of-target", "GVE84-100"),
    "3.params.none-expected.given": ("params-ignored-on-bare-commands", "GVE84-100"),
    "3.params.long-decimals": ("long-decimal-syntax-error", "GVE84-100"),
    "10.2.measured.cruise-at-v": ("velocity-ignored", "GVE84-100"),
    "10.2.measured.path-rate": ("path-speed-ignored", "GVE114-500"),
    "10.2.measured.axis-caps": ("axis-limit-ignored", "GVE84-100"),
    "10.cmd.measured.override": ("override-late", "GVE84-100"),
    "10.cmd.measured.exchange-xa": ("xa-ignored", "GVE84-100"),
    "10.cmd.measured.exchange-xu-xd": ("xu-xd-swapped", "GVE84-100"),
    "10.2.measured.trapezoid": ("accel-ignored", "GVE84-100"),
    "10.2.measured.dwell": ("dwell-ignored", "GVE84-100"),
    "10.2.measured.junction": ("junction-stops", "GVE84-100"),
    "10.2.measured.short-vector": ("short-vector-ignored", "GVE54"),
    "10.4.measured.halt-ramp": ("halt-without-ramp", "GVE84-100"),
    "10.4.measured.go-from-rest": ("go-at-speed", "GVE84-100"),
    "10.7.measured.microstep-rates": ("microstep-rates-unscaled", "GVE54"),
    "10.4.go.resumes-exactly": ("go-keeps-intcom", "GVE54"),
    "10.6.eeprom.kept-across-j": ("eeprom-forgotten-at-restart", "GVE114-500"),
}


@pytest.mark.parametrize("case_id", sorted(MADE_FOR))
def test_the_case_passes_the_emulator_and_fails_its_mutant(case_id: str) -> None:
    (c,) = select([case_id])
    mutant, profile = MADE_FOR[case_id]
    clean = run_case(c, parse_target(f"emu:{profile}"))
    assert clean.verdict == PASS, [x for x in clean.checks if not x["ok"]][:3]
    broken = run_case(c, parse_target(f"emu:{profile}", mutant=mutant))
    assert broken.verdict == FAIL, f"{case_id} does not see {mutant}"
    # the failed checks name the case's own rules
    assert {x["rule"] for x in broken.checks if not x["ok"]} <= set(c.rules)
