"""Hypothesis settings profiles for the machines (issue 4 item 5)."""

from __future__ import annotations

from hypothesis import HealthCheck, Phase, settings

_COMMON = {"suppress_health_check": list(HealthCheck), "deadline": None,
           "database": None, "print_blob": False}

PROFILES = {
    "ci": settings(max_examples=8, stateful_step_count=12, derandomize=True, **_COMMON),
    "dev": settings(max_examples=40, stateful_step_count=25, **_COMMON),
    "thorough": settings(max_examples=300, stateful_step_count=50, **_COMMON),
    # real time is dear: no shrinking (a failing example is reported as it ran)
    "hardware": settings(max_examples=3, stateful_step_count=10, derandomize=True,
                         phases=[Phase.explicit, Phase.generate], **_COMMON),
    # the mutation score: ci's examples, a failure counts as it is found (no shrinking)
    "mutation": settings(max_examples=8, stateful_step_count=12, derandomize=True,
                         phases=[Phase.explicit, Phase.generate], **_COMMON),
}


def get(name: str) -> settings:
    try:
        return PROFILES[name]
    except KeyError:
        raise ValueError(f"unknown settings profile {name!r}: {', '.join(PROFILES)}") from None
