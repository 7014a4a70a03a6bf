"""Segments and the planning of one vector (docs/motion-model.md, "Segments" and
"Planning a vector"; spec 10.2), written for the suite.

A vector's motion is a list of segments over its dominant-axis steps. ``FWD`` is a curve
from its start at rate ``v`` accelerating at ``a`` (``a = 0``: cruising); ``REV`` is a
braking curve described from its end (rate ``v`` there), of which the segment holds the
curve steps ``m0+1 .. m0+length`` (a HALT ramp is one curve split over vectors).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from math import isqrt

from conformance.motion.arith import acc_count, acc_time
from gve_fixtures.protocol import SECOND


@dataclass(frozen=True)
class Segment:
    t0: int          # the instant the segment starts (the previous step's instant)
    v: int           # FWD: rate at its start; REV: rate at the curve's end
    a: int
    length: int      # steps of the segment
    rev: bool = False
    total: int = 0   # REV: steps of the whole braking curve
    m0: int = 0      # REV: curve steps before the segment's first

    @property
    def span(self) -> int:
        """REV: the curve's duration, from its start to its last step."""
        return acc_time(self.v, self.a, self.total)

    def step_time(self, j: int) -> int:
        """The instant of the segment's step ``j`` (1..length)."""
        if not self.rev:
            return self.t0 + acc_time(self.v, self.a, j)
        return self.t0 + self.span - acc_time(self.v, self.a, self.total - self.m0 - j)

    @property
    def end(self) -> int:
        """The instant of the segment's last step."""
        return self.step_time(self.length)

    def count(self, t: int) -> int:
        """Steps of the segment done by ``t`` (a step at ``t`` is done)."""
        if t < self.t0:
            return 0
        if not self.rev:
            return min(self.length, acc_count(self.v, self.a, t - self.t0))
        x = self.span - (t - self.t0)
        curve = self.total if x <= 0 else self.total - (acc_count(self.v, self.a, x - 1) + 1)
        return max(0, min(self.length, curve - self.m0))

    def rate(self, t: int) -> int:
        """The segment's floored rate at ``t``."""
        tau = t - self.t0
        if not self.rev:
            return self.v + self.a * tau // SECOND
        return self.v + self.a * (self.span - tau) // SECOND

    def truncated(self, t: int) -> Segment:
        """The part of the segment executed by ``t``."""
        return replace(self, length=self.count(t))


def fwd(v: int, a: int, length: int) -> Segment:
    return Segment(0, v, a, length)


def rev(v: int, a: int, total: int, m0: int = 0, length: int | None = None) -> Segment:
    return Segment(0, v, a, total if length is None else length, True, total, m0)


def chain(t: int, parts: list[Segment]) -> list[Segment]:
    """Lay segments end to end from ``t``: each starts at the previous one's last step;
    zero-length ones are dropped."""
    out = []
    for seg in parts:
        if seg.length <= 0:
            continue
        seg = replace(seg, t0=t)
        out.append(seg)
        t = seg.end
    return out


def plan(t: int, r: int, vin: int, vc: int, vx: int, a: int) -> list[Segment]:
    """The segments of ``r`` remaining steps from ``t``: entry rate ``vin``, cruise ``vc``,
    exit ``vx ≤ vc``, acceleration ``a`` (docs/motion-model.md, "Planning a vector")."""
    if r <= 0:
        return []
    two_a = 2 * a
    if vin <= vc:
        up = (vc * vc - vin * vin) // two_a
        down = (vc * vc - vx * vx) // two_a
        if up + down <= r:
            return chain(t, [fwd(vin, a, up), fwd(vc, 0, r - up - down), rev(vx, a, down)])
        if vin * vin + two_a * r <= vx * vx:
            return chain(t, [fwd(vin, a, r)])
        if vx * vx + two_a * r <= vin * vin:
            return chain(t, [rev(isqrt(vin * vin - two_a * r), a, r)])
        peak2 = (two_a * r + vin * vin + vx * vx) // 2
        up = max(0, min(r, (peak2 - vin * vin) // two_a))
        return chain(t, [fwd(vin, a, up), rev(vx, a, r - up)])
    # entering faster than the cruise rate (an override slowed the vector)
    over = (vin * vin - vc * vc) // two_a
    down = (vc * vc - vx * vx) // two_a
    if over + down <= r:
        return chain(t, [rev(vc, a, over), fwd(vc, 0, r - over - down), rev(vx, a, down)])
    return chain(t, [rev(isqrt(max(vin * vin - two_a * r, vx * vx)), a, r)])


@dataclass(frozen=True)
class Params:
    """The modal parameters a vector captures when it is accepted (spec 10.1), in counter
    units: V, B and the variant's maximum rate in steps/s, A in steps/s², T in ns, $ in
    steps (on the GVE54 all scaled by the micro-step factor, docs/decisions.md)."""

    V: int
    A: int
    B: int
    dollar: int
    T: int
    max_rate: int
    VK: bool = False
    VL: tuple[int, ...] = ()


def dominant(d: tuple[int, ...]) -> int:
    return max((abs(x) for x in d), default=0)


def cruise_rate(d: tuple[int, ...], p: Params, xm: int) -> int:
    """The cruise rate of a vector ``d`` (docs/motion-model.md, "Cruise rate")."""
    n = dominant(d)
    v = p.V * xm // 100
    path2 = sum(x * x for x in d[:3])          # the A axis is not in the path (spec 10.2)
    if p.VK and path2:
        v = isqrt((v * n) ** 2 // path2)
    if n < p.dollar:
        v = min(v, p.B)
    v = min(v, p.max_rate)
    for limit, x in zip(p.VL, d, strict=False):
        if x:
            v = min(v, limit * n // abs(x))
    return max(v, 1)


def junction_rate(vc: int, p: Params, vc_next: int, a_next: int, n_next: int) -> int:
    """The exit rate of a C into the next C of ``n_next`` steps (spec 10.2): B, capped so
    that the next vector can still stop within its own length."""
    return min(p.B, vc, vc_next, isqrt(2 * a_next * n_next))
