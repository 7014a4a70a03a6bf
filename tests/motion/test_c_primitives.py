"""The C core's exact arithmetic primitives against their mathematical definitions
(docs/motion-model.md), over the full ranges of the profiles.

The references are written here from the definitions with Python integers (no square
root, no shared code with the cores), so a rounding slip on either side shows up.
"""

from __future__ import annotations

import pytest
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st

from emulator.motion.factory import c_available

pytestmark = pytest.mark.skipif(not c_available(), reason="the C stepper core is not built "
                                "(the emulator falls back to the Python twin)")

SECOND = 10**9
NEVER = 2**63 // 4          # instants saturate here ("never")
SETTINGS = settings(max_examples=400, deadline=None, derandomize=True)

rates = st.integers(0, 8_000_000)
accels = st.integers(0, 160_000_000)
counts = st.integers(0, 2**35)
durations = st.integers(0, 2**62)


def lib():
    from emulator.motion._stepper_c import lib as c
    return c


def ref_count(v: int, a: int, tau: int) -> int:
    """floor((2e9·v·tau + a·tau²) / 2e18), saturated at NEVER."""
    return min(NEVER, (2 * SECOND * v * tau + a * tau * tau) // (2 * SECOND * SECOND))


def reached(v: int, a: int, m: int, tau: int) -> bool:
    return 2 * SECOND * v * tau + a * tau * tau >= 2 * SECOND * SECOND * m


def ref_time(v: int, a: int, m: int) -> int:
    """The smallest tau ≥ 0 reaching step m, found by doubling and bisection."""
    hi = 1
    while not reached(v, a, m, hi):
        hi *= 2
    lo = 0
    while lo < hi:
        mid = (lo + hi) // 2
        if reached(v, a, m, mid):
            hi = mid
        else:
            lo = mid + 1
    return min(lo, NEVER)


@given(rates, accels, durations)
@example(8_000_000, 160_000_000, 2**62)
@example(1, 0, 2**62)
@example(0, 1, 1_414_213_562)          # half a step short of one step at a = 1
@SETTINGS
def test_acc_count_is_the_floor_of_the_distance(v, a, tau):
    assume(v or a)
    assert lib().st_acc_count(v, a, tau) == ref_count(v, a, tau)


@given(rates, accels, st.integers(0, 2**20))
@SETTINGS
def test_acc_count_short_durations(v, a, tau):
    assume(v or a)
    assert lib().st_acc_count(v, a, tau) == ref_count(v, a, tau)


@given(rates, accels, counts)
@example(8_000_000, 160_000_000, 2**35)
@example(1, 0, 2**35)                 # cruising at 1 step/s: saturates at "never"
@example(0, 1, 2**35)
@example(0, 1, 1)
@SETTINGS
def test_acc_time_is_the_first_instant_reaching_the_step(v, a, m):
    assume(v or a)
    tau = lib().st_acc_time(v, a, m)
    assert tau == ref_time(v, a, m)
    if tau < NEVER:
        assert reached(v, a, m, tau)
        assert tau == 0 or not reached(v, a, m, tau - 1)


@given(rates, accels, counts)
@SETTINGS
def test_count_and_time_are_inverse(v, a, m):
    assume(v or a)
    c = lib()
    tau = c.st_acc_time(v, a, m)
    assume(tau < NEVER)
    assert c.st_acc_count(v, a, tau) >= m
    if tau > 0:
        assert c.st_acc_count(v, a, tau - 1) < m


@given(st.integers(0, 2**128 - 1))
@example(2**128 - 1)
@example((2**64 - 1) ** 2)
@example((2**64 - 1) ** 2 - 1)
@example(2**126)
@example(2**126 - 1)
@SETTINGS
def test_isqrt_u128_is_exact(n):
    r = lib().st_isqrt_u128(n >> 64, n & (2**64 - 1))
    assert r * r <= n < (r + 1) * (r + 1)


@given(st.integers(0, 2**64 - 1))
@SETTINGS
def test_isqrt_u128_of_squares_and_neighbours(r):
    c = lib()
    for n in (r * r, r * r + 2 * r, max(0, r * r - 1)):
        got = c.st_isqrt_u128(n >> 64, n & (2**64 - 1))
        assert got * got <= n < (got + 1) * (got + 1)


@given(rates, accels, counts, st.integers(1, 3000))
@example(0, 10_000_000, 0, 3000)            # a ramp from rest: its first steps are far apart
@example(0, 1, 0, 50)
@example(14_142, 0, 0, 3000)                # cruising: the increments alternate by 1 ns
@example(1, 0, 2**35 - 3000, 3000)          # 1 step/s: the instants near "never"
@example(8_000_000, 160_000_000, 2**20, 3000)
@SETTINGS
def test_the_walk_gives_acc_time_step_after_step(v, a, m, count):
    # pulse trains take a curve's instants one from the other (no division, no square
    # root): every one must be the first instant reaching its step, as acc_time's
    from emulator.motion._stepper_c import ffi
    assume(v or a)
    out = ffi.new("int64_t[]", count)
    got = lib().st_walk(v, a, m, count, out)
    if got < 0:
        # refused only beyond what any plan reaches: a rate past 2**61 / 2e9 steps/s
        # (plans stay below the unit's maximum rate) or an instant at "never"
        tau = ref_time(v, a, m + count - 1)
        assert tau >= NEVER or 2 * SECOND * v + 2 * a * tau >= 2**61
        return
    for i, tau in enumerate(out):
        assert reached(v, a, m + i, tau)
        assert tau == 0 or not reached(v, a, m + i, tau - 1)
