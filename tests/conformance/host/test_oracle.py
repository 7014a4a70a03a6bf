"""The oracle names the first difference between the clean run's motion and a fault run's:
the vector, and whether it ran twice, never ran, or ran under another setting."""

from __future__ import annotations

from conformance.host.oracle import difference
from conformance.host.unitview import Executed

MODAL = (("V", 1000),)
A, B, C = (Executed("C", (v, 0, 0), MODAL) for v in (1, 2, 3))


def test_the_same_motion():
    assert difference([A, B, C], [A, B, C]) is None


def test_a_vector_run_twice():
    said = difference([A, B, C], [A, B, B, C])
    assert said is not None and "C2,0,0" in said and "twice" in said


def test_a_vector_lost():
    said = difference([A, B, C], [A, C])
    assert said is not None and "C2,0,0" in said and "never ran" in said


def test_a_vector_under_another_setting():
    slow = Executed("C", (2, 0, 0), (("V", 500),))
    said = difference([A, B, C], [A, slow, C])
    assert said is not None and "C2,0,0" in said and "V500" in said and "V1000" in said
