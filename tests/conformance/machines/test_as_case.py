"""A machine meeting bytes no reading allows where a value belongs (``0,²²``) FAILs its
case as the runner FAILs a directed case's, never an ERROR, under the response grammar's
rule (every check names the rule it judges)."""

from __future__ import annotations

import re

from conformance.run.runner import run_case
from conformance.run.selection import select
from conformance.targets import parse_target
from conformance.targets.emu import EmuTarget
from conformance.verdicts.verdict import ALWAYS, FAIL, UNREADABLE

#: a number in an answer, spoiled with digits of another script
_NUMBER = re.compile(rb"^0,(-?[0-9]+)")


class Spoiling:
    """An emulated unit's port whose answers carry ``²`` where their first number was."""

    def __init__(self, port) -> None:
        self._port = port

    def read_until(self, expected: bytes = b"\n", size: int | None = None) -> bytes:
        return _NUMBER.sub(b"0,\xb2\xb2", self._port.read_until(expected, size))

    def __getattr__(self, name: str):
        return getattr(self._port, name)


class SpoilingTarget(EmuTarget):
    def connect(self, address):
        port, baud, virtual, line = super().connect(address)
        return Spoiling(port), baud, virtual, line


def test_unreadable_answers_fail_a_machine_as_the_unit_s_fault():
    (case,) = select(["4.machine.refusals-read-back"])
    plain = parse_target("emu:GVE84-100")
    target = SpoilingTarget(plain.info, plain.profile, plain.address, plain.baud, plain.url)
    r = run_case(case, target, "mutation")
    assert r.verdict == FAIL, (r.notes, r.checks)
    (failed,) = r.failed_checks
    assert failed["tag"] == ALWAYS and failed["rule"] == UNREADABLE
    assert "the unit's answer cannot be read" in failed["what"]
    assert '"\\xB2\\xB2" where a decimal number belongs' in failed["what"]
