"""Kinematics of the GVE114 interpolator: vectors and trapezoidal ramps.

All speeds are in pulses/s of the vector's dominant axis (the axis with the
most pulses), accelerations in pulses/s^2, instants in integer nanoseconds.
A plan is a list of phases (ts, te, s0, s1, v0, acc): between the instants
ts and te the progress along the vector (in dominant-axis pulses) is
s0 + v0*dt + acc*dt^2/2.
"""
import math

NS = 1_000_000_000


class Vector:
    __slots__ = ('kind', 'd', 'L', 'V', 'A', 'B', 'vk', 'short', 'k')

    def __init__(self, kind, d, V, A, B, vk, short_lim):
        self.kind = kind          # 'L' or 'C'
        self.d = list(d)          # pulses per axis X, Y, Z, A (A already coupled)
        self.V = V                # requested speed (pulses/s), changed by XA/XU/XD
        self.A = A                # acceleration, pulses/s^2
        self.B = B                # braking speed at its end (pulses/s)
        self.vk = vk              # VK speed correction active when queued
        self.recompute(short_lim)

    def recompute(self, short_lim=None):
        self.L = max(abs(x) for x in self.d)
        if short_lim is not None:
            self.short = self.L < short_lim
        e = math.sqrt(sum(x * x for x in self.d[:3]))
        # VK: V is the speed along the XYZ path; convert to dominant-axis rate
        self.k = (self.L / e) if (self.vk and e > 0) else 1.0

    def delta(self, s):
        """Per-axis pulses done at progress s (0..L), truncated toward the start."""
        L = self.L
        if L == 0:
            return [0, 0, 0, 0]
        if s >= L:
            return list(self.d)
        out = []
        for x in self.d:
            n = int(math.floor(abs(x) * s / L + 1e-9))
            out.append(n if x >= 0 else -n)
        return out


def ns(sec):
    return int(round(sec * NS))


def profile(t0, s0, v0, L, vc, ve, a):
    """Plan from progress s0 at speed v0 to the end L, cruising at most vc and
    ending at ve (if reachable).  Returns (phases, v_end)."""
    rem = L - s0
    if rem <= 0:
        return [], v0
    segs = []  # (duration s, v_start, acc, distance)
    if v0 >= ve and v0 * v0 - ve * ve >= 2 * a * rem:
        vend = math.sqrt(max(0.0, v0 * v0 - 2 * a * rem))
        segs.append(((v0 - vend) / a, v0, -a, rem))
    elif v0 < ve and ve * ve - v0 * v0 >= 2 * a * rem:
        vend = math.sqrt(v0 * v0 + 2 * a * rem)
        segs.append(((vend - v0) / a, v0, a, rem))
    else:
        if v0 > vc:
            vp = vc
        else:
            vp = min(vc, math.sqrt((2 * a * rem + v0 * v0 + ve * ve) / 2))
        d1 = abs(vp * vp - v0 * v0) / (2 * a)
        d3 = (vp * vp - ve * ve) / (2 * a)
        d2 = max(0.0, rem - d1 - d3)
        if vp != v0:
            segs.append((abs(vp - v0) / a, v0, a if vp > v0 else -a, d1))
        if d2 > 0:
            segs.append((d2 / vp, vp, 0.0, d2))
        if vp > ve:
            segs.append(((vp - ve) / a, vp, -a, d3))
        vend = ve
    phases = []
    c = 0.0
    s = s0
    for dur, vs, acc, dist in segs:
        ts = t0 + ns(c)
        c += dur
        te = t0 + ns(c)
        s1 = s + dist
        phases.append([ts, te, s, s1, vs, acc])
        s = s1
    phases[-1][3] = L
    return phases, vend


def stop_profile(t0, s0, v0, L, a):
    """Decelerate at a from v0.  Returns (phases, v_end, stops_inside)."""
    rem = L - s0
    if v0 <= 0:
        return [], 0.0, True
    need = v0 * v0 / (2 * a)
    if need <= rem + 1e-9:
        dur = v0 / a
        phases = [[t0, t0 + ns(dur), s0, min(L, s0 + need), v0, -a]]
        return phases, 0.0, True
    vend = math.sqrt(max(0.0, v0 * v0 - 2 * a * rem))
    dur = (v0 - vend) / a
    phases = [[t0, t0 + ns(dur), s0, L, v0, -a]]
    return phases, vend, False


def evaluate(phases, t):
    """(s, v) at instant t for a plan."""
    if not phases:
        return None
    ph = phases[0]
    for p in phases:
        if p[0] <= t:
            ph = p
        else:
            break
    ts, te, s0, s1, v0, acc = ph
    if t >= te:
        return s1, v0 + acc * (te - ts) / NS
    dt = (t - ts) / NS
    s = s0 + v0 * dt + 0.5 * acc * dt * dt
    v = v0 + acc * dt
    lo, hi = (s0, s1) if s1 >= s0 else (s1, s0)
    return min(max(s, lo), hi), max(v, 0.0)
