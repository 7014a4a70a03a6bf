"""What the CLI's tests share."""

from __future__ import annotations

import pytest


@pytest.fixture
def fairness_on_one_profile(monkeypatch: pytest.MonkeyPatch) -> str:
    """`fairness` tries a reading on the first profile of FIRST only: the tests of how the
    CLI grades, scores and reports a reading need one profile's catalogue and diff (a few
    seconds), not three; the gate (every reading on one profile per family) and the slow
    test of every reading alone run them all."""
    from conformance.cli import fairness
    monkeypatch.setattr(fairness, "FIRST", fairness.FIRST[:1])
    return fairness.FIRST[0]
