"""What the CLI's tests share."""

from __future__ import annotations

import pytest


@pytest.fixture
def fairness_on_one_profile(monkeypatch: pytest.MonkeyPatch) -> str:
    """`fairness` tries a reading on the first profile of FIRST only, and its diff runs the
    probes and the drawn sequences, not the matrix's cells (some 650 sequences): the tests
    of how the CLI grades, scores and reports a reading need one profile's catalogue and
    diff (a second or two), not three; the gate (every reading on one profile per family,
    every cell) and the slow test of every reading alone run them all."""
    from conformance.cli import fairness
    from conformance.diff import engine, matrix
    monkeypatch.setattr(fairness, "FIRST", fairness.FIRST[:1])
    for module in (engine, matrix):
        monkeypatch.setattr(module, "cells", lambda profile, options: [])
    return fairness.FIRST[0]
