"""Fault injectors and verdict grading."""

from __future__ import annotations

import pytest

from conformance.link.faults import FrameFault
from conformance.verdicts.verdict import FAIL, INFO, NON_STRICT, PASS, grade, worst

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
    assert FrameFault("host", kind, params).apply(FRAME) == expected


def test_unknown_faults_are_refused():
    with pytest.raises(ValueError):
        FrameFault("host", "melt")
    with pytest.raises(ValueError):
        FrameFault("sideways", "drop")


def test_grading_follows_the_spec_table():
    assert grade("M", False) == FAIL and grade("M-ex", False) == FAIL
    assert grade("D", False) == NON_STRICT and grade("D", True) == FAIL
    assert grade("D-info", True) == INFO
    assert worst([]) == PASS and worst([INFO, NON_STRICT]) == NON_STRICT
