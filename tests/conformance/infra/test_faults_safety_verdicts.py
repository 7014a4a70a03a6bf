"""Fault injectors, the safety guard on real units, and verdict grading."""

from __future__ import annotations

import pytest

from conformance.link.faults import Fault
from conformance.link.safety import Guard, SafetyStop
from conformance.verdict import FAIL, INFO, NON_STRICT, PASS, grade, worst

FRAME = b"!0V1000\r"


@pytest.mark.parametrize(("kind", "params", "expected"), [
    ("drop", {}, []),
    ("drop-byte", {"at": 2}, [(b"!01000\r", 0.0)]),
    ("corrupt", {"at": 2, "xor": 0x20}, [(b"!0v1000\r", 0.0)]),
    ("truncate", {"keep": 3}, [(b"!0V", 0.0)]),
    ("delay", {"at": 4, "seconds": 0.2}, [(b"!0V1", 0.0), (b"000\r", 0.2)]),
    ("split", {"size": 4, "seconds": 0.01}, [(b"!0V1", 0.0), (b"000\r", 0.01)]),
])
def test_injectors(kind, params, expected):
    assert Fault("host", kind, params).apply(FRAME) == expected


def test_unknown_faults_are_refused():
    with pytest.raises(ValueError):
        Fault("host", "melt")
    with pytest.raises(ValueError):
        Fault("sideways", "drop")


def test_envelope():
    g = Guard(enforce=True, max_travel=100, allow_destructive=False)
    g.check("L50,0,0")
    g.accepted("L50,0,0")
    with pytest.raises(SafetyStop):
        g.check("C60,0,0")
    g.check("C-150,0,0")
    with pytest.raises(SafetyStop):
        g.check("J")
    with pytest.raises(SafetyStop):
        g.check("EW01,00")
    with pytest.raises(SafetyStop):
        g.check("WX,-20000,1000,2000,500")


def test_destructive_writes_are_backed_up():
    g = Guard(enforce=True, max_travel=100, allow_destructive=True)
    assert g.check("EFW30,1.5") == [0x30, 0x31, 0x32, 0x33]
    assert Guard(enforce=False, max_travel=0, allow_destructive=False).check("J") == []


def test_grading_follows_the_spec_table():
    assert grade("M", False) == FAIL and grade("M-ex", False) == FAIL
    assert grade("D", False) == NON_STRICT and grade("D", True) == FAIL
    assert grade("D-info", True) == INFO
    assert worst([]) == PASS and worst([INFO, NON_STRICT]) == NON_STRICT
