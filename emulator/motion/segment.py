"""Segments of a velocity profile, and the trapezoid planner (spec 10.2).

A vector's motion is a list of segments, each covering a run of its dominant-axis steps:

- ``FWD``: from rate ``v`` with acceleration ``a`` ≥ 0 (``a = 0`` is cruising). Step j of
  the segment (1-based) falls at ``t0 + acc_time(v, a, j)``.
- ``REV``: braking to rate ``v`` at the end of a curve of ``total`` steps, described
  backwards from its end: curve step c falls at ``t0 + T - acc_time(v, a, total - c)``
  with ``T = acc_time(v, a, total)``. A segment holds curve steps ``m0+1 .. m0+length``,
  so one braking curve (a HALT ramp) can run on through several vectors.

Everything is integer and closed form: counting the steps up to an instant and finding
the instant of a step cost the same whatever the lengths.
"""

from __future__ import annotations

from math import isqrt
from typing import NamedTuple

from emulator.motion.arith import acc_count, acc_time, sat
from gve_fixtures.protocol import SECOND

FWD = 0
REV = 1


class Segment(NamedTuple):
    kind: int      # FWD or REV
    t0: int        # the curve's anchor instant
    v: int         # FWD: entry rate; REV: the rate at the curve's end
    a: int         # acceleration (FWD) or deceleration (REV), steps/s²
    total: int     # REV: the curve's length in steps; FWD: = length
    m0: int        # REV: curve steps before this segment; FWD: 0
    length: int    # steps in this segment
    k0: int        # the vector's dominant steps done before this segment
    tdec: int      # REV: acc_time(v, a, total); FWD: 0
    start: int     # instant at which the segment begins
    end: int       # instant of its last step


def forward(t0: int, v: int, a: int, length: int, k0: int) -> Segment:
    return Segment(FWD, t0, v, a, length, 0, length, k0, 0, t0,
                   sat(t0 + acc_time(v, a, length)))


def reverse(t0: int, v: int, a: int, total: int, m0: int, length: int, k0: int) -> Segment:
    tdec = acc_time(v, a, total)
    start = sat(t0 + tdec - acc_time(v, a, total - m0))
    end = sat(t0 + tdec - acc_time(v, a, total - m0 - length))
    return Segment(REV, t0, v, a, total, m0, length, k0, tdec, start, end)


def count(s: Segment, t: int) -> int:
    """Steps of the segment taken at or before ``t``."""
    if t < s.start:
        return 0
    if t >= s.end:
        return s.length
    if s.kind == FWD:
        return min(s.length, acc_count(s.v, s.a, t - s.t0))
    x = s.tdec - (t - s.t0)            # time left until the curve's end, ≥ 1 here
    curve = s.total - (acc_count(s.v, s.a, x - 1) + 1)
    return min(max(curve - s.m0, 0), s.length)


def step_instant(s: Segment, j: int) -> int:
    """The instant of the segment's step ``j`` (1 ≤ j ≤ length)."""
    if s.kind == FWD:
        return sat(s.t0 + acc_time(s.v, s.a, j))
    return sat(s.t0 + s.tdec - acc_time(s.v, s.a, s.total - s.m0 - j))


def rate(s: Segment, t: int) -> int:
    """The (floored) rate of the segment's curve at ``t``, clamped to the segment."""
    tau = min(max(t, s.start), s.end) - s.t0
    if s.kind == FWD:
        return s.v + s.a * tau // SECOND
    return s.v + s.a * max(s.tdec - tau, 0) // SECOND


def plan(t: int, k0: int, r: int, vin: int, vc: int, vx: int, a: int) -> list[Segment]:
    """The profile of ``r`` remaining steps from instant ``t`` (after ``k0`` steps):
    from rate ``vin`` to cruise ``vc`` and down to exit ``vx`` ≤ vc, at acceleration ``a``.

    Up to three segments: change to the cruise rate, cruise, brake to the exit rate.
    When the vector is too short for all three, the rate peaks where the accelerating
    and braking curves meet (or the vector is one curve when even that cannot be)."""
    if r <= 0:
        return []
    two_a = 2 * a
    down = (vc * vc - vx * vx) // two_a
    pieces: list[tuple[int, int, int, int]]       # (kind, rate, acceleration, length)
    if vin <= vc:
        up = (vc * vc - vin * vin) // two_a
        if up + down <= r:
            pieces = [(FWD, vin, a, up), (FWD, vc, 0, r - up - down), (REV, vx, a, down)]
        elif vin * vin + two_a * r <= vx * vx:
            pieces = [(FWD, vin, a, r)]           # accelerating all the way
        elif vx * vx + two_a * r <= vin * vin:
            pieces = [(REV, isqrt(vin * vin - two_a * r), a, r)]
        else:
            peak2 = (two_a * r + vin * vin + vx * vx) // 2
            up = min(max((peak2 - vin * vin) // two_a, 0), r)
            pieces = [(FWD, vin, a, up), (REV, vx, a, r - up)]
    else:
        over = (vin * vin - vc * vc) // two_a     # brake to the cruise rate first
        if over + down <= r:
            pieces = [(REV, vc, a, over), (FWD, vc, 0, r - over - down), (REV, vx, a, down)]
        else:
            pieces = [(REV, max(vx, isqrt(max(0, vin * vin - two_a * r))), a, r)]
    segments: list[Segment] = []
    for kind, v, acc, length in pieces:
        if length <= 0:
            continue
        if kind == FWD:
            s = forward(t, v, acc, length, k0)
        else:
            s = reverse(t, v, acc, length, 0, length, k0)
        segments.append(s)
        t, k0 = s.end, k0 + length
    return segments
