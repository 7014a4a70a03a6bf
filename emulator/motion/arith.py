"""The exact integer arithmetic of the motion model (docs/motion-model.md).

Both stepper cores use these definitions; the C core computes the same functions with
64-bit instants and 128-bit products. Every result is defined mathematically (the
smallest integer such that ...), so any correct implementation gives the same numbers.

Units: instants ``t`` and durations ``tau`` in integer nanoseconds; rates ``v`` in
counter steps per second; accelerations ``a`` in steps per second².
"""

from __future__ import annotations

from math import isqrt

from gve_fixtures.protocol import SECOND

_S2 = 2 * SECOND * SECOND          # 2e18: positions are counted in 1/(2e18) steps
#: "Never": instants saturate here, far beyond any run (about 73 years).
NEVER = (1 << 63) // 4


def sat(t: int) -> int:
    """Clamp an absolute instant or a duration to :data:`NEVER`."""
    return t if t < NEVER else NEVER


def acc_count(v: int, a: int, tau: int) -> int:
    """Steps taken ``tau`` ns after a phase starts at rate ``v`` with acceleration ``a``:
    floor((2e9·v·tau + a·tau²) / 2e18)."""
    return (2 * SECOND * v * tau + a * tau * tau) // _S2


def acc_time(v: int, a: int, m: int) -> int:
    """The smallest tau ≥ 0 with 2e9·v·tau + a·tau² ≥ 2e18·m (the instant of step m)."""
    if m <= 0:
        return 0
    target = _S2 * m
    b = 2 * SECOND * v
    if a == 0:
        tau = -(-target // b)
    else:
        tau = (isqrt(b * b + 4 * a * target) - b) // (2 * a)
        # the square root is floored: correct to the exact definition
        while tau > 0 and b * (tau - 1) + a * (tau - 1) * (tau - 1) >= target:
            tau -= 1
        while b * tau + a * tau * tau < target:
            tau += 1
    return sat(tau)


def stop_distance(v: int, a: int) -> int:
    """Whole steps needed to brake from ``v`` to rest: floor(v² / 2a)."""
    return v * v // (2 * a)


def axis_count(k: int, d: int, n: int) -> int:
    """Signed steps of an axis moving ``d`` after ``k`` of the dominant axis's ``n`` steps:
    round_half_up(k·|d|/n), so every vector ends exactly on its target (spec 10.2)."""
    if d == 0 or n == 0:
        return 0
    c = (2 * k * abs(d) + n) // (2 * n)
    return c if d > 0 else -c


def first_step_reaching(c: int, d: int, n: int) -> int:
    """The smallest dominant step k at which an axis moving ``d`` has taken ``c`` ≥ 1
    steps (the inverse of :func:`axis_count`)."""
    ad = abs(d)
    # (2k|d| + n) // (2n) >= c  <=>  2k|d| >= 2nc - n
    return max(0, -(-(2 * n * c - n) // (2 * ad)))
