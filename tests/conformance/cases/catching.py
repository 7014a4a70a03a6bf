"""A case made to catch a mutant: it FAILs the mutant through the check of the rule the
mutant breaks, and PASSes the clean emulator on the same profile."""

from __future__ import annotations

from conformance.run.runner import run_case
from conformance.run.selection import select
from conformance.targets import parse_target
from conformance.verdicts.verdict import FAIL, PASS


def assert_catches(case_id: str, rule: str, mutant: str, profile: str, *,
                   only: bool = True) -> None:
    """``only``: the rule's check is the only one that fails; otherwise any other that
    fails must be one of the case's own rules."""
    (c,) = select([case_id])
    broken = run_case(c, parse_target(f"emu:{profile}", mutant=mutant), "mutation")
    assert broken.verdict == FAIL
    failed = {k["rule"] for k in broken.checks if not k["ok"]}
    assert failed == {rule} if only else rule in failed and failed <= set(c.rules)
    assert run_case(c, parse_target(f"emu:{profile}"), "mutation").verdict == PASS
