"""The two curve functions of the motion model in exact integer arithmetic
(docs/motion-model.md, "Units" and "The two curve functions"), written for the suite.

Instants and durations are integer nanoseconds; rates are steps per second; an
acceleration is steps per second squared (the unit's ``A`` × 1000).
"""

from __future__ import annotations

from math import isqrt

from gve_fixtures.protocol import SECOND

#: an instant that never comes (saturation, as the model's)
NEVER = 2**63 // 4
_TWO_S = 2 * SECOND
_TWO_S2 = 2 * SECOND * SECOND


def acc_count(v: int, a: int, tau: int) -> int:
    """Steps a curve starting at rate ``v`` and accelerating at ``a`` has done ``tau``
    ns after its start: floor((2e9·v·τ + a·τ²) / 2e18)."""
    if tau <= 0:
        return 0
    return (_TWO_S * v * tau + a * tau * tau) // _TWO_S2


def acc_time(v: int, a: int, m: int) -> int:
    """The instant (ns after the curve's start) of its step ``m``: the least τ ≥ 0 with
    2e9·v·τ + a·τ² ≥ 2e18·m; :data:`NEVER` when the curve never gets there."""
    if m <= 0:
        return 0
    need = _TWO_S2 * m
    if a == 0:
        if v <= 0:
            return NEVER
        tau = -(-need // (_TWO_S * v))
    else:
        b = _TWO_S * v
        tau = max(0, (isqrt(b * b + 4 * a * need) - b) // (2 * a))
        # the square root is floored: settle on the least τ meeting the inequality
        while b * tau + a * tau * tau < need:
            tau += 1
        while tau > 0 and b * (tau - 1) + a * (tau - 1) ** 2 >= need:
            tau -= 1
    return min(tau, NEVER)


def axis_steps(d: int, n: int, k: int) -> int:
    """Steps axis component ``d`` of a vector of dominant length ``n`` has taken after
    ``k`` dominant steps: round_half_up(k·|d|/n) with the sign of ``d`` (spec 10.2)."""
    if n == 0 or d == 0:
        return 0
    steps = (2 * k * abs(d) + n) // (2 * n)
    return steps if d > 0 else -steps
