"""F on a full queue behind a halt: bit 5 is the manual's, RUN for the vectors queued
after the `H` our reading [D] (the manual's RUN: "je zpracováván vektor")."""

from __future__ import annotations

import shlex
import sys
from pathlib import Path

from conformance.run.runner import run
from conformance.run.selection import select
from conformance.targets import parse_target
from conformance.verdicts.verdict import NON_STRICT
from gve_fixtures.profile import load_profile

CORPUS = Path(__file__).resolve().parents[3] / "corpus"
#: a simulator written from M114 alone whose vectors queued behind a halt hold no RUN
PENDING_NOT_RUN = [sys.executable, str(CORPUS / "gve114-d" / "sim.py"), "--cosim",
                   "--model", "GVE114-500"]


def test_a_full_queue_behind_a_halt_without_run_is_our_readings_point():
    target = parse_target("exec:" + shlex.join(PENDING_NOT_RUN), profile="GVE114-500",
                          allow_destructive=True,
                          max_travel=load_profile("GVE114-500").vector_range)
    target.preflight()
    [case] = run([target], select(["10.1.queue.executing-counts"])).results
    assert case.verdict == NON_STRICT
    assert {c["rule"] for c in case.failed_checks} == {"10.3.st6.run-pending"}
