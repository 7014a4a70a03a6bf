"""F on a full queue behind a halt: bit 5 is the manual's, RUN for the vectors queued
after the `H` our reading [D] (the manual's RUN: "je zpracováván vektor")."""

from __future__ import annotations

from conformance.verdicts.verdict import NON_STRICT
from tests.conformance.cases.corpus_unit import case_on


def test_a_full_queue_behind_a_halt_without_run_is_our_readings_point():
    # gve114-d, written from M114 alone: its vectors queued behind a halt hold no RUN
    case = case_on("gve114-d", "GVE114-500", "10.1.queue.executing-counts")
    assert case.verdict == NON_STRICT
    assert {c["rule"] for c in case.failed_checks} == {"10.3.st6.run-pending"}
