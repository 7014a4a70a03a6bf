"""The oracle's words for a motion that differs from the clean run's."""

from __future__ import annotations

from conformance.host.oracle import difference
from conformance.host.unitview import Step

MODAL = (("V", 1000),)
A, B, C = (Step("C", (v, 0, 0), MODAL) for v in (1, 2, 3))


def test_the_same_motion():
    assert difference([A, B, C], [A, B, C]) is None


def test_a_vector_run_twice():
    assert difference([A, B, C], [A, B, B, C]) == "`C2,0,0` ran twice"


def test_a_vector_lost():
    assert difference([A, B, C], [A, C]) == "`C2,0,0` (step 2 of the job) never ran"


def test_a_vector_under_another_setting():
    slow = Step("C", (2, 0, 0), (("V", 500),))
    assert difference([A, B, C], [A, slow, C]) == \
        "step 2, `C2,0,0`, ran with V500 instead of V1000"
