#!/usr/bin/env python3
"""GVE84 hardware interpolator -- software simulator of one unit.

Written from the vendor manual (GVE84, "Plna verze dokumentace v1.0") alone.
Structure follows the way the firmware would be ported from the MCU:

  * Step timer ISR, 100 kHz (TICK = 10 us).  A step is emitted on a timer tick,
    never between ticks.  The ramp generator of the running vector is an exact
    integer/rational trapezoid (integer steps/s, integer steps/s^2); the ISR's
    DDA emits major-axis step j on the first tick at which the ramp position has
    reached j - 1/2 (accumulator preset to one half), minor axes follow by
    Bresenham (midpoint) from the major count.  Instead of calling the ISR
    100 000 times a second the simulator evaluates its outcome in closed form
    between events (identical result, tick for tick).
  * UART receive state machine (idle -> address -> body -> CR), watchdog timer.
  * Command dispatcher (chapter 12.5), answers per 12.6, checksums 12.3.2,
    packets 12.3.3, reset 12.4, EEPROM chapter 11.
  * Co-simulation front end (given/cosim.md) and test rig (given/rig.md).

Every place where the manual had to be read one way or another is numbered in
READINGS.md; the numbers are cited in comments as [Rnn].
"""
import sys
import json
import math
import re
from fractions import Fraction
from collections import deque

# ----------------------------------------------------------------- constants
TICK_NS = 10_000                 # step-timer period: 10 us      [R01]
TPS = 1_000_000_000 // TICK_NS   # ticks per second
RESTART_NS = 2_000_000_000       # "cca po 2s" (12.4)              [R24]
WATCHDOG_NS = 100_000_000        # frame must complete in 100 ms  [R12]
QUEUE_LEN = 64                   # "buffer pro 64 vektoru"        [R15]
MAXI = 2147483647
VERSION = "IP84 v3 27.1.2010"    # 12.2                           [R33]
CPU_ID = "27011001"              # ddmmrrpp                        [R34]
MODELS = {"GVE84-15": 15000, "GVE84-50": 50000, "GVE84-100": 100000}
MAXFRAME = 96                    # receive buffer                 [R13]

# ST6 bits (12.5.11)
B_STOP, B_FREE, B_INTCOM, B_RUN, B_INTA = 0x01, 0x02, 0x10, 0x40, 0x80

RE_INT = re.compile(r'^[+-]?[0-9]+$')
RE_HEX = re.compile(r'^[0-9A-Fa-f]+$')
DEFER = "defer"      # answer comes later (H, W) or was already sent (J)
NOANS = "noans"      # no answer at all (*S)


def ceil_tick(t_ns):
    return -((-t_ns) // TICK_NS)


def frac_isqrt(x):
    """floor(sqrt(x)) for a non-negative Fraction, as a Fraction (integer)."""
    if x <= 0:
        return Fraction(0)
    return Fraction(math.isqrt(math.floor(x)))


class BadParam(Exception):
    def __init__(self, code):
        self.code = code


# ----------------------------------------------------------------- ramp plan
class Plan:
    """Ramp of one vector: phases of constant acceleration from instant t0.

    s is the continuous major-axis position (steps, from the vector's start),
    velocities in steps/s, times in seconds (Fractions).  The ramp itself runs
    in continuous time (the ramp generator's arithmetic is exact); steps are
    emitted by the 100 kHz step ISR only, on the first tick at which the ramp
    has passed j - 1/2.  For ticks before t0 the step count is j_pre (what the
    previous ramp had emitted)."""

    def __init__(self, t0, s0, v0, j_pre):
        self.t0 = Fraction(t0)
        self.s0 = Fraction(s0)
        self.v0 = Fraction(v0)
        self.j_pre = j_pre
        self.ph = []
        self.T = Fraction(0)
        self.s_end = self.s0
        self.v_end = self.v0

    def add(self, dur, a):
        if dur <= 0:
            return
        s, v = self.s_end, self.v_end
        self.ph.append((self.T, dur, s, v, a))
        self.T += dur
        self.s_end = s + v * dur + a * dur * dur / 2
        self.v_end = v + a * dur

    def sv_at(self, tau):
        if tau <= 0:
            return self.s0, self.v0
        for (ts, d, s, v, a) in self.ph:
            if tau < ts + d:
                x = tau - ts
                return s + v * x + a * x * x / 2, v + a * x
        return self.s_end, self.v_end

    def sv_ns(self, t_ns):
        return self.sv_at(Fraction(t_ns, 10 ** 9) - self.t0)

    def j_tick(self, k):
        tk = Fraction(k, TPS)
        if tk < self.t0:
            return self.j_pre
        s, _ = self.sv_at(tk - self.t0)
        return max(self.j_pre, math.floor(s + Fraction(1, 2)))   # [R02]

    def end_ns(self):
        return math.ceil((self.t0 + self.T) * 10 ** 9)

    def tick_of_step(self, m):
        """First tick at which step m has been emitted (None: never)."""
        if self.j_pre >= m:
            return None
        lo = math.ceil(self.t0 * TPS)
        hi = math.ceil((self.t0 + self.T) * TPS)
        if self.j_tick(hi) < m:
            return None
        while lo < hi:
            mid = (lo + hi) // 2
            if self.j_tick(mid) >= m:
                hi = mid
            else:
                lo = mid + 1
        return lo


def ns2s(t_ns):
    return Fraction(t_ns, 10 ** 9)


QD = 1 << 32


def quant(x):
    """Ramp state carried into a new ramp is held to 32 fraction bits, as the
    firmware's fixed-point registers would (keeps the arithmetic bounded)."""
    return Fraction(math.floor(Fraction(x) * QD), QD)


def build_plan(t0, s0, v0, j_pre, n, vc, v1, A):
    """Trapezoid from (s0, v0) to (n, v1), cruise at most vc, accel A."""
    p = Plan(t0, s0, v0, j_pre)
    p.vc, p.v1 = vc, v1
    v0 = Fraction(v0)
    r = Fraction(n) - Fraction(s0)
    if r <= 0:
        return p
    vc = Fraction(max(1, vc))
    v1 = min(Fraction(v1), vc)
    A = Fraction(A)
    if v0 * v0 > v1 * v1 + 2 * A * r:          # cannot brake in time: harder
        a2 = (v0 * v0 - v1 * v1) / (2 * r)
        p.add((v0 - v1) / a2, -a2)
        return p
    vp2 = (2 * A * r + v0 * v0 + v1 * v1) / 2
    if vp2 >= vc * vc:
        peak = vc
    else:
        peak = frac_isqrt(vp2)
        if peak <= 0 or peak < max(v0, v1):
            q = 1 << 20
            peak = Fraction(math.isqrt(math.floor(vp2 * q * q)), q)
        peak = max(peak, v0, v1)
    d1 = abs(peak * peak - v0 * v0) / (2 * A)
    d3 = (peak * peak - v1 * v1) / (2 * A)
    d2 = r - d1 - d3
    p.add(abs(peak - v0) / A, A if peak >= v0 else -A)
    if d2 > 0:
        p.add(d2 / peak, Fraction(0))
    p.add((peak - v1) / A, -A)
    return p


def build_brake(t0, s0, v0, j_pre, n, A, can_pass):
    """Stop ramp from (s0, v0) at A.  Returns (plan, stops_inside)."""
    p = Plan(t0, s0, v0, j_pre)
    v0 = Fraction(v0)
    A = Fraction(A)
    r = Fraction(n) - Fraction(s0)
    if v0 <= 0:
        return p, True
    d = v0 * v0 / (2 * A)
    if d <= r:
        p.add(v0 / A, -A)
        return p, True
    if can_pass and r > 0:                     # brake on into the next C vector
        v1 = frac_isqrt(v0 * v0 - 2 * A * r)
        a2 = (v0 * v0 - v1 * v1) / (2 * r)
        p.add((v0 - v1) / a2, -a2)
        return p, False
    if r > 0:
        a2 = v0 * v0 / (2 * r)
        p.add(v0 / a2, -a2)
    return p, True


# ----------------------------------------------------------------- vectors
class Vec:
    __slots__ = ("kind", "d", "n", "j", "A", "V", "B", "short", "vk", "axis")

    def __init__(self, kind, d, A, V, B, short, vk, axis=None):
        self.kind = kind
        self.d = list(d)
        self.n = max(abs(x) for x in d)
        self.j = 0
        self.A, self.V, self.B = A, V, B
        self.short, self.vk = short, vk
        self.axis = axis

    def m(self, j):
        """Axis offsets after j major steps (Bresenham midpoint)."""   # [R03]
        n = self.n
        if n == 0:
            return [0, 0, 0]
        out = []
        for x in self.d:
            ax = abs(x)
            k = (j * ax + n // 2) // n
            out.append(k if x >= 0 else -k)
        return out

    def copy(self):
        v = Vec(self.kind, self.d, self.A, self.V, self.B, self.short, self.vk, self.axis)
        v.j = self.j
        return v


# ----------------------------------------------------------------- the unit
class Unit:
    def __init__(self, model="GVE84-100", address=0, send=None, eeprom_path=None):
        self.model = model
        self.fmax = MODELS[model]
        self.address = address
        self.send_cb = send
        self.eeprom_path = eeprom_path
        self.ee = bytearray([0xFF] * 256)          # erased               [R28]
        self.ee[0x01] = 0x00                       # relay = spindle (11)
        if eeprom_path:
            try:
                with open(eeprom_path, "rb") as f:
                    data = f.read(256)
                self.ee[:len(data)] = data
            except OSError:
                pass
        self.inputs = {0: 0xFF, 1: 0xFF, 2: 0xFF}  # rig levels, pulled up
        self.switches = {}                         # rig reference points
        self.cnt = [0, 0, 0]
        self.phys = [0, 0, 0]
        self.exc = [[0, 0], [0, 0], [0, 0]]
        self.last_answer = None
        self.restart_until = None
        self.brake_timer = None
        self._reset(0, cold=True)
        self.restart_until = None                  # simulator starts ready [R25]
        if self.ee[0x01] == 0x08:
            self.outputs &= ~0x02

    # -------------------------------------------------------- reset (12.4)
    def _reset(self, now, cold=False):
        self.st = [0] * 6                          # ST0..ST5
        self.st6 = 0                               # STOP/FREE/INTCOM/INTA latch bits
        self.A = 20                                # kpulses/s^2
        self.V = 1000
        self.short_lim = 512
        self.B = self.fmax                         # "bez omezeni"         [R05]
        self.T = 5                                 # ms                    [R06]
        self.vk = False                            # VN                    [R07]
        self.VL = [100000, 100000, 100000]         # no limit              [R08]
        self.XM = 100
        self.cnt = [0, 0, 0]
        self.outputs = 0xFF
        self.cs_on = False
        self.index = 0
        self.q = []
        self.cap = QUEUE_LEN
        self.kept = None
        self.plan = None
        self.halting = False
        self.stops_inside = True
        self.mev = None                            # (time_ns, kind, arg)
        self.pending = None                        # deferred answer (H, W)
        self.silent_pending = False
        self.wref = None                           # W state
        self.in_packet = False
        self.pkt_count = 0
        self.pkt_err = 0
        self.rx_state = 0                          # 0 idle, 1 address, 2 body
        self.rx_buf = []
        self.rx_addr = None
        self.rx_overflow = False
        self.wd_deadline = None
        self.last_rest = now
        # EEPROM configuration is read at reset                          [R29]
        e5 = self.ee[0x05]
        self.pol = [1 if (e5 >> i) & 1 else -1 for i in range(3)]
        self.relay_fn = self.ee[0x01]
        self.brake_timer = None
        if self.relay_fn == 0x08 and not cold:
            fd = min(self.ee[0xFD], 50)
            self.brake_timer = now + fd * 100_000_000

    def power_on(self, now):
        self._halt_dead(now)
        self.pending = None
        self._reset(now)
        self.restart_until = now + RESTART_NS
        self.last_rest = self.restart_until

    def _halt_dead(self, now):
        """Axes stop where they are (reset / power loss)."""
        if self.plan is not None and self.q:
            self._commit(self.plan.j_tick(now // TICK_NS))
        self.plan = None

    # -------------------------------------------------------- positions
    def _commit(self, j):
        v = self.q[0] if self.q else None
        if v is None or j == v.j:
            return
        a = v.m(v.j)
        b = v.m(j)
        for i in range(3):
            dd = b[i] - a[i]
            self.cnt[i] += dd
            self.phys[i] += dd * self.pol[i]
            self._exc(i)
        v.j = j

    def _exc(self, i):
        p = self.phys[i]
        if p < self.exc[i][0]:
            self.exc[i][0] = p
        if p > self.exc[i][1]:
            self.exc[i][1] = p

    def positions(self, now):
        """(counters, physical) at the instant now, without committing."""
        cnt, phys = list(self.cnt), list(self.phys)
        if self.plan is not None and self.q:
            v = self.q[0]
            j = self.plan.j_tick(now // TICK_NS)
            a, b = v.m(v.j), v.m(j)
            for i in range(3):
                cnt[i] += b[i] - a[i]
                phys[i] += (b[i] - a[i]) * self.pol[i]
        return cnt, phys

    # -------------------------------------------------------- status
    @property
    def inta(self):
        return 1 if self.st6 & B_INTA else 0

    def run_bit(self):
        return bool(self.q) or self.wref is not None

    def sr6(self):
        v = self.st6 & (B_STOP | B_FREE | B_INTCOM | B_INTA)
        if self.run_bit():
            v |= B_RUN
        return v

    def flag(self):
        v = self.sr6()
        if len(self.q) >= self.cap:
            v |= 0x20
        return v

    def moving(self):
        """'za chodu': axes moving, about to move, or vectors being processed."""
        if self.plan is not None or self.wref is not None:
            return True
        return bool(self.q) and not self.inta

    # -------------------------------------------------------- speeds
    def cruise(self, v):
        if v.kind in ('W1', 'W2'):
            return max(1, min(v.V, self.fmax))
        V = v.V * self.XM // 100                                      # [R20]
        B = v.B
        n = v.n
        if n == 0:
            return max(1, min(V, self.fmax))
        if v.vk:                                                      # [R18]
            ln = math.isqrt(sum(x * x for x in v.d))
            if ln > 0:
                V = V * n // ln
                B = B * n // ln
        for i in range(3):
            if v.d[i]:
                V = min(V, self.VL[i] * n // abs(v.d[i]))             # [R19]
        V = min(V, self.fmax)
        if v.short:
            V = min(V, B)                                             # [R17]
        return max(1, V)

    def exit_speed(self):
        """Speed q[0] may leave at: B-limited junction, look-ahead to a stop."""
        q = self.q
        ex = 0
        for k in range(len(q) - 1, 0, -1):
            cur, prev = q[k], q[k - 1]
            if cur.kind != 'C' or prev.kind != 'C':
                ex = 0
                continue
            rem = cur.n - cur.j
            reach = math.isqrt(ex * ex + 2 * cur.A * 1000 * rem)
            pb = prev.B
            if prev.vk and prev.n:
                ln = math.isqrt(sum(x * x for x in prev.d))
                if ln:
                    pb = pb * prev.n // ln
            ex = min(reach, pb, self.cruise(prev), self.cruise(cur))
        return ex

    # -------------------------------------------------------- executor
    def _set_plan(self, plan, inside=True):
        self.plan = plan
        self.stops_inside = inside
        self._calc_mev()

    def _calc_mev(self):
        self.mev = None
        p = self.plan
        if p is None:
            return
        v = self.q[0]
        cands = []
        if self.halting and self.stops_inside:
            m = math.floor(p.s_end + Fraction(1, 2))
            m = max(min(m, v.n), p.j_pre)
            cands.append((p.end_ns(), 'rest', m))                     # [R38]
        else:
            cands.append((p.end_ns(), 'end', None))
        w = self.wref
        if w is not None and w['phase'] in (1, 2) and w.get('target') is not None:
            m = w['target']
            if m <= v.n:
                k = p.tick_of_step(m)
                if k is not None:
                    cands.append((k * TICK_NS, 'hit' if w['phase'] == 1 else 'release', m))
        self.mev = min(cands, key=lambda c: c[0])

    def try_start(self, now):
        if self.plan is not None or not self.q or self.inta:
            return
        if self.restart_until is not None:
            return
        if self.wref is not None and self.q[0].kind not in ('W1', 'W2'):
            return
        v = self.q[0]
        t0 = ns2s(max(now, self.last_rest + self.T * 1_000_000))    # [R06]
        self.halting = False
        if v.kind == 'W2':
            # back-off: start/stop speed, no ramp                       [R31]
            p = Plan(t0, v.j, v.V, v.j)
            p.add(Fraction(v.n - v.j, v.V), Fraction(0))
            self._set_plan(p)
        else:
            self._set_plan(build_plan(t0, v.j, 0, v.j, v.n, self.cruise(v),
                                      self.exit_speed(), v.A * 1000))

    def replan(self, now):
        """Speeds or the queue changed while a vector runs."""
        p = self.plan
        if p is None or self.halting or not self.q:
            return
        v = self.q[0]
        if v.kind in ('W1', 'W2'):
            return
        if now >= p.end_ns():
            return
        t0 = ns2s(now)
        if t0 <= p.t0:
            self._set_plan(build_plan(p.t0, p.s0, p.v0, p.j_pre, v.n, self.cruise(v),
                                      self.exit_speed(), v.A * 1000))
            return
        vc, v1 = self.cruise(v), self.exit_speed()
        if getattr(p, 'vc', None) == vc and getattr(p, 'v1', None) == v1:
            return
        s, vel = p.sv_at(t0 - p.t0)
        jp = p.j_tick(ceil_tick(now) - 1)
        self._set_plan(build_plan(t0, quant(s), quant(vel), jp, v.n, vc, v1, v.A * 1000))

    def start_brake(self, now):
        """Stop ramp (H, interrupt, W switch).  Returns True if at rest now."""
        p = self.plan
        if p is None:
            return True
        v = self.q[0]
        t0 = ns2s(now)
        if t0 <= p.t0 and p.v0 == 0:         # still in the T pause: nothing moves
            self.plan = None
            self.mev = None
            self.st6 &= ~B_STOP
            return True
        s, vel = p.sv_at(t0 - p.t0)
        s, vel = quant(s), quant(vel)
        jp = p.j_tick(ceil_tick(now) - 1)
        can_pass = (v.kind == 'C' and len(self.q) > 1 and self.q[1].kind == 'C')
        bp, inside = build_brake(t0, s, vel, jp, v.n, v.A * 1000, can_pass)
        self.halting = True
        self._set_plan(bp, inside)
        if inside and bp.T == 0:
            self._rest_at(now, self.mev[2])
            return True
        return False

    def _rest_at(self, t, j):
        self._commit(j)
        v = self.q[0]
        if v.kind == 'W1':
            self.plan = None
            self.mev = None
            self.halting = False
            self.st6 &= ~B_STOP
            self.last_rest = t
            self._w_after_approach(t)
            return
        if j >= v.n:
            self.q.pop(0)
        self._stopped(t)

    def _stopped(self, t):
        self.plan = None
        self.mev = None
        self.halting = False
        self.st6 &= ~B_STOP
        self.last_rest = t
        if self.pending is not None and self.pending[0] == 'H':
            ans = self.pending[1]
            self.pending = None
            self._answer_now(t, ans)
        self.try_start(t)

    def _motion_event(self, t):
        kind, arg = self.mev[1], self.mev[2]
        v = self.q[0]
        p = self.plan
        if kind == 'rest':
            self._rest_at(t, arg)
        elif kind == 'hit':
            self.wref['target'] = None
            self.start_brake(t)
        elif kind == 'release':
            self._commit(arg)
            self._w_done(t, ok=True)
        else:  # vector end
            self._commit(v.n)
            vend = p.v_end
            self.q.pop(0)
            self.plan = None
            self.mev = None
            if v.kind == 'W1':
                self.last_rest = t
                self._w_done(t, ok=False)
                return
            if v.kind == 'W2':
                self.last_rest = t
                self._w_done(t, ok=False)
                return
            nxt = self.q[0] if self.q else None
            if nxt is not None and nxt.kind == 'C' and v.kind == 'C' and vend > 0:
                t0 = ns2s(t)                  # next vector picked up at this instant
                vend = quant(vend)
                if self.halting:
                    can_pass = len(self.q) > 1 and self.q[1].kind == 'C'
                    bp, inside = build_brake(t0, nxt.j, vend, nxt.j, nxt.n,
                                             nxt.A * 1000, can_pass)
                    self._set_plan(bp, inside)
                    if inside and bp.T == 0:
                        self._rest_at(t, nxt.j)
                else:
                    self._set_plan(build_plan(t0, nxt.j, vend, nxt.j, nxt.n,
                                              self.cruise(nxt), self.exit_speed(),
                                              nxt.A * 1000))
            else:
                self._stopped(t)

    # -------------------------------------------------------- W (12.5.7)
    def _ref_active(self, axis):
        bit = (self.inputs[1] >> axis) & 1
        pol = (self.st[2] >> axis) & 1
        return bit == pol

    def _w_start(self, now, axis, n2, n3, n4, n5):
        d = [0, 0, 0]
        d[axis] = n2
        v = Vec('W1', d, self.A, n3, n3, False, False, axis)
        self.wref = {'axis': axis, 'n4': n4, 'n5': n5, 'phase': 1, 'target': None,
                     'dir': 1 if n2 > 0 else -1}
        self._w_target_approach(v)
        self.q.insert(0, v)
        if self.wref['target'] == 0:       # standing on it
            self.wref['target'] = None
            self._rest_at(now, 0)
            return
        self.try_start(now)

    def _w_target_approach(self, v):
        w = self.wref
        ax = w['axis']
        pdir = w['dir'] * self.pol[ax]
        if ax in self.switches:
            m = (self.switches[ax] - self.phys[ax]) * pdir
            w['target'] = m if 0 <= m <= v.n else None
            w['mode'] = 'switch'
        else:
            w['mode'] = 'input'
            w['target'] = 0 if self._ref_active(ax) else None

    def _w_after_approach(self, t):
        w = self.wref
        self.q.pop(0)
        w['phase'] = 2
        ax = w['axis']
        d = [0, 0, 0]
        d[ax] = -w['dir'] * w['n4']
        v = Vec('W2', d, self.A, w['n5'], w['n5'], False, False, ax)
        pdir = -w['dir'] * self.pol[ax]
        if w['mode'] == 'switch':
            m = (self.switches[ax] + pdir - self.phys[ax]) * pdir
            w['target'] = m if m >= 0 else 0
            if w['target'] > v.n:
                w['target'] = None
        else:
            w['target'] = None if self._ref_active(ax) else 0
        self.q.insert(0, v)
        if w['target'] == 0:
            self._w_done(t, ok=True)
            return
        self.try_start(t)

    def _w_done(self, t, ok):
        w = self.wref
        if self.q and self.q[0].kind in ('W1', 'W2'):
            self.q.pop(0)
        self.plan = None
        self.mev = None
        self.halting = False
        self.wref = None
        self.last_rest = t
        if ok:
            self.cnt[w['axis']] = 0                                   # [R30]
        if self.pending is not None and self.pending[0] == 'W':
            self.pending = None
            self._answer_now(t, self._fmt(0 if ok else 5, []))
        self._check_intr(t)

    def _w_input_changed(self, now):
        w = self.wref
        if w is None or self.plan is None or w['mode'] != 'input':
            return
        ax = w['axis']
        if w['phase'] == 1 and self.mev and self.mev[1] != 'rest' and self._ref_active(ax):
            w['target'] = None
            self.start_brake(now)
        elif w['phase'] == 2 and not self._ref_active(ax):
            self._commit(self.plan.j_tick(now // TICK_NS))
            self._w_done(now, ok=True)

    # -------------------------------------------------------- interrupts
    def _check_intr(self, now):
        if self.wref is not None:
            return                                                    # [R32]
        active = 0
        for i in range(3):
            if self._ref_active(i):
                active |= 1 << i
        pend = active & self.st[0] & 0x07
        new = pend & ~self.st[4]
        if new:
            self.st[4] |= new
            self.st6 |= B_INTA
            if self.plan is not None and not self.halting:
                self.st6 |= B_STOP
                self.start_brake(now)

    # -------------------------------------------------------- events
    def next_event(self):
        c = []
        if self.restart_until is not None:
            c.append(self.restart_until)
        if self.wd_deadline is not None:
            c.append(self.wd_deadline)
        if self.mev is not None:
            c.append(self.mev[0])
        if self.brake_timer is not None:
            c.append(self.brake_timer)
        return min(c) if c else None

    def process_due(self, t):
        while True:
            ne = self.next_event()
            if ne is None or ne > t:
                return
            if self.restart_until is not None and self.restart_until == ne:
                self.restart_until = None
                self.last_rest = ne
                self._check_intr(ne)
                self.try_start(ne)
            elif self.wd_deadline is not None and self.wd_deadline == ne:
                self._watchdog(ne)
            elif self.mev is not None and self.mev[0] == ne:
                self._motion_event(ne)
            elif self.brake_timer is not None and self.brake_timer == ne:
                self.brake_timer = None
                self.outputs &= ~0x02                                 # [R29]

    # -------------------------------------------------------- UART receive
    def rx_byte(self, t, c):
        self.process_due(t)
        if self.restart_until is not None:
            return                                  # deaf while restarting
        if self.pending is not None:
            return                                  # busy in H/W      [R14]
        if c == 0x21:                               # '!' starts a frame
            self.rx_state = 1
            self.rx_buf = []
            self.rx_addr = None
            self.rx_overflow = False
            self.wd_deadline = t + WATCHDOG_NS
            return
        if self.rx_state == 0:
            return
        if c == 0x0A:
            return                                  # LF ignored       [R13]
        if self.rx_state == 1:
            if c == 0x0D:
                self._rx_reset()
                return
            self.rx_addr = c
            self.rx_state = 2
            return
        if c == 0x0D:
            addr, body, ovf = self.rx_addr, bytes(self.rx_buf), self.rx_overflow
            self._rx_reset()
            if addr == 0x30 + self.address:
                self._frame(t, body, ovf)
            return
        if len(self.rx_buf) < MAXFRAME:
            self.rx_buf.append(c)
        else:
            self.rx_overflow = True

    def _rx_reset(self):
        self.rx_state = 0
        self.rx_buf = []
        self.rx_addr = None
        self.wd_deadline = None

    def _watchdog(self, t):
        addr = self.rx_addr
        self._rx_reset()
        if addr == 0x30 + self.address:
            if self.in_packet:
                if not self.pkt_err:
                    self.pkt_err = 2                                  # [R11]
            else:
                self._answer_now(t, self._fmt(2, []))

    # -------------------------------------------------------- answers (12.6)
    def _fmt(self, code, params):
        s = "%X" % ((self.inta << 3) | code)
        for p in params:
            s += "," + p
        if self.cs_on:
            s += ","
            s += "%02X" % (sum(s.encode("latin-1")) & 0xFF)
        return s + "\r"

    def _answer_now(self, t, s):
        self.last_answer = s
        if self.send_cb:
            self.send_cb(t, s.encode("latin-1"))

    # -------------------------------------------------------- dispatcher
    def _frame(self, t, body, overflow):
        text = "!" + chr(0x30 + self.address) + body.decode("latin-1")
        cmd = body.decode("latin-1")
        code = None
        if overflow:
            code = 4
        elif self.cs_on:                                              # 12.3.2
            k = cmd.rfind(",")
            ok = False
            if k >= 0 and re.match(r'^[0-9A-Fa-f]{2}$', cmd[k + 1:]):
                total = sum(text[:2 + k + 1].encode("latin-1")) & 0xFF
                ok = total == int(cmd[k + 1:], 16)
            if ok:
                cmd = cmd[:k]
            else:
                code = 4                                              # [R09]
        if self.in_packet and not cmd.startswith("*"):
            if code is None and not self.pkt_err:
                code, params = self._exec(t, cmd, silent=True)
                if code in (DEFER, NOANS):
                    code = 0
                if code == 0:
                    self.pkt_count += 1
                    self.index = (self.index + 1) & 0xFF
                else:
                    self.pkt_err = code
            elif code is not None and not self.pkt_err:
                self.pkt_err = code
            return
        if code is not None:
            self._answer_now(t, self._fmt(code, []))
            return
        code, params = self._exec(t, cmd, silent=False)
        if code == NOANS:                     # *S (counted), J (index reset)
            if cmd == "*S":
                self.index = (self.index + 1) & 0xFF
            return
        if code == DEFER:                     # H, W: answered when done
            self.index = (self.index + 1) & 0xFF
            return
        if cmd == ">":
            if self.last_answer is not None:
                self._answer_now(t, self.last_answer)
            else:
                self._answer_now(t, self._fmt(0, []))
            return
        ans = self._fmt(code, params)
        if code == 0 and cmd != "@":
            self.index = (self.index + 1) & 0xFF                      # [R35]
        self._answer_now(t, ans)

    def _int(self, s, lo, hi):
        if not RE_INT.match(s):
            raise BadParam(4)
        v = int(s)
        if v < lo or v > hi:
            raise BadParam(5)
        return v

    def _hex(self, s):
        if not RE_HEX.match(s):
            raise BadParam(4)
        v = int(s, 16)
        if v > 0xFF:
            raise BadParam(5)
        return v

    def _exec(self, t, cmd, silent):
        try:
            return self._exec2(t, cmd, silent)
        except BadParam as e:
            return e.code, []

    def _noargs(self, rest):
        if rest:
            raise BadParam(4)

    def _exec2(self, t, cmd, silent):
        if not cmd:
            return 3, []
        c0 = cmd[0]
        # ---- identification
        if cmd == "?":
            return 0, [VERSION]
        if cmd == "Q":
            return 0, [CPU_ID]
        if cmd == "@":
            return 0, [str(self.index)]
        if cmd == ">":
            return 0, []
        if cmd.startswith("%"):
            if cmd == "%+":
                self.cs_on = True
                return 0, []
            if cmd == "%-":
                self.cs_on = False
                return 0, []
            return 4, []
        if cmd.startswith("*"):
            if cmd == "*S":
                self.in_packet = True
                self.pkt_count = 0
                self.pkt_err = 0
                return NOANS, []
            if cmd.startswith("*E"):
                if not self.in_packet:
                    return 4, []                                      # [R10]
                n = self._int(cmd[2:], 0, MAXI)
                self.in_packet = False
                code = self.pkt_err
                if not code and n != self.pkt_count:
                    code = 2                                          # [R10]
                return code, [str(self.pkt_count)]
            return 3, []
        # ---- vectors
        if c0 in "LC":
            parts = cmd[1:].split(",")
            if len(parts) != 3:
                return 4, []
            d = [self._int(x, -MAXI, MAXI) for x in parts]
            return self._vector(t, c0, d), []
        if c0 == "T":
            self.T = self._int(cmd[1:], 1, 24)
            return 0, []
        if c0 == "$":
            self.short_lim = self._int(cmd[1:], 1, MAXI)
            return 0, []
        if c0 == "A":
            self.A = self._int(cmd[1:], 1, 1000)                      # [R16]
            return 0, []
        if c0 == "B":
            self.B = self._int(cmd[1:], 10, 100000)
            return 0, []
        if cmd.startswith("VL"):
            parts = cmd[2:].split(",")
            if len(parts) not in (3, 4):
                return 4, []
            vals = [self._int(x, 10, 100000) for x in parts]          # [R19]
            self.VL = vals[:3]
            return 0, []
        if cmd == "VK":
            self.vk = True
            return 0, []
        if cmd == "VN":
            self.vk = False
            return 0, []
        if c0 == "V":
            self.V = self._int(cmd[1:], 10, self.fmax)                # [R16]
            return 0, []
        if cmd.startswith("X"):
            return self._exchange(t, cmd), []
        # ---- position
        if cmd == "P":
            c, _ = self.positions(t)
            return 0, [str(c[0]), str(c[1])]
        if cmd == "PF":
            c, _ = self.positions(t)
            return 0, [str(c[0]), str(c[1]), str(c[2])]
        if c0 == "N":
            if cmd == "N":
                if self.run_bit():
                    return 7, []
                self.cnt = [0, 0, 0]
                return 0, []
            ax = "XYZ".find(cmd[1].upper()) if len(cmd) > 1 else -1
            if ax < 0:
                return 4, []
            val = self._int(cmd[2:], -MAXI, MAXI)
            if self.run_bit():
                return 7, []                                          # [R22]
            self.cnt[ax] = val
            return 0, []
        if c0 == "W":
            parts = cmd[1:].split(",")
            if len(parts) != 5:
                return 4, []
            ax = "XYZ".find(parts[0].upper()) if len(parts[0]) == 1 else -1
            if ax < 0:
                return 4, []
            n2 = self._int(parts[1], -MAXI, MAXI)
            n3 = self._int(parts[2], 10, self.fmax)
            n4 = self._int(parts[3], 1, MAXI)
            n5 = self._int(parts[4], 10, self.fmax)
            if n2 == 0:
                return 5, []
            if self.run_bit():
                return 7, []
            if not silent:
                self.pending = ('W', None)
            self._w_start(t, ax, n2, n3, n4, n5)
            return (0, []) if silent else (DEFER, [])
        # ---- queue handling
        if cmd == "K":
            if self.moving() and not (self.inta and self.plan is None and self.wref is None):
                return 7, []
            if self.kept is not None:
                return 5, []                                          # [R26]
            self.kept = ([v.copy() for v in self.q], self.st[4], self.st[5], self.st6)
            self.q = []
            self.st[4] = self.st[5] = 0
            self.st6 = 0
            self.cap = 1
            self._check_intr(t)
            return 0, []
        if cmd == "R":
            if self.moving():
                return 7, []
            if self.kept is None:
                return 0, []                                          # [R26]
            q, s4, s5, s6 = self.kept
            self.kept = None
            self.q = q
            self.st[4], self.st[5], self.st6 = s4, s5, s6
            self.cap = QUEUE_LEN
            self._check_intr(t)
            self.try_start(t)
            return 0, []
        if cmd == "H":
            self.st6 |= B_INTA | B_INTCOM
            if self.plan is None:
                return 0, []
            if not self.halting:
                self.st6 |= B_STOP
                if self.start_brake(t):
                    return 0, []
            if silent:
                return 0, []
            self.pending = ('H', self._fmt(0, []))   # INTA already 1
            return DEFER, []
        if cmd == "D":
            if self.moving():
                return 7, []
            self.q = []
            self.st[4] = self.st[5] = 0
            self.st6 = 0
            self._check_intr(t)
            return 0, []
        if cmd == "G":
            if not self.inta:
                return 6, []
            if self.plan is not None:
                return 7, []                                          # [R27]
            self.st6 &= ~(B_INTA | B_INTCOM | B_STOP)
            self.st[4] = self.st[5] = 0
            self._check_intr(t)
            if not self.q:
                return 6, []
            self.try_start(t)
            return 0, []
        if cmd == "F":
            return 0, ["%02X" % self.flag()]
        if cmd == "J":
            self._halt_dead(t)
            ans = self._fmt(0, [])
            self._answer_now(t, ans)
            self.power_on(t)                                          # [R23]
            return NOANS, []
        # ---- EEPROM
        if cmd.startswith("ER"):
            a = self._hex(cmd[2:])
            return 0, ["%02X" % self.ee[a]]
        if cmd.startswith("EW"):
            parts = cmd[2:].split(",")
            if len(parts) != 2:
                return 4, []
            a, x = self._hex(parts[0]), self._hex(parts[1])
            self.ee[a] = x
            if self.eeprom_path:
                try:
                    with open(self.eeprom_path, "wb") as f:
                        f.write(bytes(self.ee))
                except OSError:
                    pass
            return 0, []
        # ---- outputs / inputs / status
        if c0 == "O":
            parts = cmd[1:].split(",")
            if len(parts) != 2:
                return 4, []
            port = self._int(parts[0], 0, 255)
            x = self._hex(parts[1])
            if port != 0:
                return 5, []
            self.outputs = x
            return 0, []
        if c0 == "I":
            port = self._int(cmd[1:], 0, 255)
            if port != 1:
                return 5, []                                          # [R21]
            return 0, ["%02X" % self.inputs[1]]
        if cmd.startswith("SR"):
            n = self._int(cmd[2:], 0, 255)
            if n > 6:
                return 5, []
            return 0, ["%02X" % (self.sr6() if n == 6 else self.st[n])]
        if cmd.startswith("SW"):
            parts = cmd[2:].split(",")
            if len(parts) != 2:
                return 4, []
            n = self._int(parts[0], 0, 255)
            x = self._hex(parts[1])
            if n > 6:
                return 5, []
            if n == 6:
                return self._sw6(t, x), []
            self.st[n] = x
            if n in (0, 2):
                self._check_intr(t)
            return 0, []
        return 3, []

    def _sw6(self, t, x):                                             # [R36]
        old = self.st6
        self.st6 = x & (B_STOP | B_FREE | B_INTCOM | B_INTA)
        if (x & B_STOP) and self.plan is not None and not self.halting:
            self.st6 |= B_INTA
            self.start_brake(t)
        elif (x & B_STOP) and self.plan is None:
            self.st6 &= ~B_STOP
        if (old & B_INTA) and not (self.st6 & B_INTA) and self.plan is None:
            self.try_start(t)
        return 0

    def _vector(self, t, kind, d):
        if kind == 'L':
            # L is taken only with an empty queue and RUN=0           [R04]
            if self.q or self.wref is not None:
                return 1
        else:
            if self.kept is not None:
                return 1                                              # [R26]
            if len(self.q) >= self.cap:
                return 1
        n = max(abs(x) for x in d)
        v = Vec(kind, d, self.A, self.V, self.B, n < self.short_lim, self.vk)
        self.q.append(v)
        if self.plan is None:
            self.try_start(t)
        else:
            self.replan(t)
        return 0

    def _exchange(self, t, cmd):
        vs = list(self.q)
        if self.kept is not None:
            pass
        if cmd == "XA":
            for v in vs:
                v.V = self.V
        elif cmd == "XU":
            for v in vs:
                v.V = min(self.fmax, v.V + v.V // 16)
        elif cmd == "XD":
            for v in vs:
                v.V = max(10, v.V - v.V // 16)
        elif cmd.startswith("XM"):
            self.XM = self._int(cmd[2:], 1, 1000)                     # [R20]
        else:
            return 3
        self.replan(t)
        return 0

    # -------------------------------------------------------- rig
    def rig_in(self, now, port, val):
        self.inputs[port] = val
        if port == 1:
            self._w_input_changed(now)
            self._check_intr(now)

    def state(self, now):
        cnt, phys = self.positions(now)
        exc = []
        for i in range(3):
            lo, hi = self.exc[i]
            exc.append([min(lo, phys[i]), max(hi, phys[i])])
        st = ["%02X" % x for x in self.st] + ["%02X" % self.sr6()]
        return {
            "profile": self.model,
            "addresses": [self.address],
            "position": cnt,
            "physical": phys,
            "excursion": exc,
            "status": st,
            "outputs": "%02X" % self.outputs,
            "spindle": 0,
            "rate_position": None,
            "rate": None,
            "inputs": {str(k): "%02X" % v for k, v in sorted(self.inputs.items())},
            "time_ns": now,
            "queue": len(self.q),
            "index": self.index,
            "checksums": self.cs_on,
            "modal": {"V": self.V, "A": self.A, "B": self.B, "$": self.short_lim,
                      "T": self.T, "VK": self.vk, "VL": self.VL, "XM": self.XM},
            "kept": self.kept is not None,
            "packet_open": self.in_packet,
            "eeprom": self.eeprom_path,
            "restarting": self.restart_until is not None,
        }


# ----------------------------------------------------------------- co-simulation
class Cosim:
    def __init__(self, model, eeprom=None, out=sys.stdout):
        self.out = out
        self.now = 0
        self.b = round(10 * 10 ** 9 / 115200)
        self.rxq = deque()        # (instant, byte) towards the unit
        self.txfifo = deque()     # bytes handed over, not yet begun
        self.txcur = None         # (byte, completion instant)
        self.unit = Unit(model, send=self._send, eeprom_path=eeprom)

    def _send(self, t, data):
        self.txfifo.extend(data)
        if self.txcur is None:
            self.txcur = (self.txfifo.popleft(), t + self.b)

    def advance(self, limit, cr_stop):
        got = []
        u = self.unit
        while True:
            ts = []
            te = u.next_event()
            if te is not None:
                ts.append(te)
            if self.txcur is not None:
                ts.append(self.txcur[1])
            if self.rxq:
                ts.append(self.rxq[0][0])
            t = min(ts) if ts else None
            if t is None or t > limit:
                self.now = limit
                return got, False
            if t < self.now:
                t = self.now
            self.now = t
            if te is not None and te <= t:
                u.process_due(t)
                continue
            if self.txcur is not None and self.txcur[1] <= t:
                byte, tc = self.txcur
                got.append((tc, byte))
                self.txcur = (self.txfifo.popleft(), tc + self.b) if self.txfifo else None
                if byte == 0x0D and cr_stop:
                    return got, True
                continue
            if self.rxq and self.rxq[0][0] <= t:
                _, byte = self.rxq.popleft()
                u.rx_byte(t, byte)

    def rx_lines(self, got):
        lines = []
        i = 0
        while i < len(got):
            t0, b0 = got[i]
            hx = "%02X" % b0
            k = i + 1
            while k < len(got) and got[k][0] == got[k - 1][0] + self.b:
                hx += "%02X" % got[k][1]
                k += 1
            lines.append("rx %d %s" % (t0, hx))
            i = k
        return lines

    def do_tx(self, hexs, T=None):
        data = bytes.fromhex(hexs)
        for i, c in enumerate(data):
            self.rxq.append((self.now + (i + 1) * self.b, c))
        end = self.now + len(data) * self.b
        got, _ = self.advance(end, False)
        cr = any(b == 0x0D for _, b in got)
        if T is not None and not cr:
            g2, _ = self.advance(T, True)
            got += g2
        return self.rx_lines(got) + ["now %d" % self.now]

    def next_instant(self):
        c = []
        te = self.unit.next_event()
        if te is not None:
            c.append(te)
        if self.txcur is not None:
            c.append(self.txcur[1])
        c = [x for x in c if x > self.now]
        return min(c) if c else None

    def handle(self, line):
        w = line.split()
        if not w:
            return None
        cmd = w[0]
        num = re.compile(r'^[0-9]{1,20}$')
        try:
            if cmd == "tx":
                if len(w) not in (2, 3):
                    return ["error: tx HEX [T]"]
                hx = w[1]
                if len(hx) % 2 or not re.match(r'^[0-9A-Fa-f]*$', hx) or not hx:
                    return ["error: bad hex"]
                T = None
                if len(w) == 3:
                    if not num.match(w[2]):
                        return ["error: bad number"]
                    T = int(w[2])
                    if T < self.now + (len(hx) // 2) * self.b:
                        return ["error: T before the end of the bytes"]
                return self.do_tx(hx, T)
            if cmd == "batch":
                args = w[1:]
                if not args or len(args) % 2:
                    return ["error: batch D HEX [D HEX ...]"]
                pairs = []
                for i in range(0, len(args), 2):
                    if not num.match(args[i]):
                        return ["error: bad number"]
                    hx = args[i + 1]
                    if len(hx) % 2 or not hx or not re.match(r'^[0-9A-Fa-f]*$', hx):
                        return ["error: bad hex"]
                    pairs.append((int(args[i]), hx))
                out = []
                for D, hx in pairs:
                    T = self.now + (len(hx) // 2) * self.b + D
                    r = self.do_tx(hx, T)
                    out += r
                    cr = False
                    for l in r:
                        if l.startswith("rx "):
                            hb = bytes.fromhex(l.split()[2])
                            if 0x0D in hb:
                                cr = True
                    if not cr:
                        break                                   # batch-stops
                return out
            if cmd == "until":
                if len(w) != 2 or not num.match(w[1]):
                    return ["error: until T"]
                T = int(w[1])
                if T < self.now:
                    return ["error: until before now"]
                got, _ = self.advance(T, True)
                return self.rx_lines(got) + ["now %d" % self.now]
            if cmd == "next":
                if len(w) != 1:
                    return ["error: next takes no argument"]
                n = self.next_instant()
                return ["next none" if n is None else "next %d" % n]
            if cmd == "baud":
                if len(w) != 2 or not num.match(w[1]) or int(w[1]) == 0:
                    return ["error: baud N"]
                self.b = round(10 * 10 ** 9 / int(w[1]))
                return ["ok"]
            if cmd == "state":
                if len(w) > 2 or (len(w) == 2 and w[1] != "@%d" % self.unit.address):
                    return ["error: state [@ADDRESS]"]
                return [json.dumps(self.unit.state(self.now))]
            if cmd == "in":
                w = self._strip_addr(w)
                if w is None or len(w) != 3 or w[1] not in ("0", "1", "2") \
                        or not re.match(r'^[0-9A-Fa-f]{2}$', w[2]):
                    return ["error: in PORT XX"]
                self.unit.rig_in(self.now, int(w[1]), int(w[2], 16))
                return ["ok"]
            if cmd == "switch":
                w = self._strip_addr(w)
                if w is None or len(w) != 3 or w[1] not in ("X", "Y", "Z"):
                    return ["error: switch AXIS POS|none (axes X Y Z)"]
                ax = "XYZ".index(w[1])
                if w[2] == "none":
                    self.unit.switches.pop(ax, None)
                elif re.match(r'^[+-]?[0-9]{1,20}$', w[2]):
                    self.unit.switches[ax] = int(w[2])
                else:
                    return ["error: bad position"]
                return ["ok"]
            if cmd == "power-on":
                if len(w) > 2:
                    return ["error: power-on"]
                self.unit.power_on(self.now)
                return ["ok"]
            if cmd == "rate":
                return ["error: the GVE84's rate is fixed at order time"]
            if cmd == "help":
                return ["commands: tx HEX [T] | batch D HEX ... | until T | next | baud N | "
                        "in PORT HEX | switch AXIS POS|none | power-on | state | quit"]
        except (ValueError, OverflowError) as e:
            return ["error: %s" % e]
        return ["error: unknown command '%s'" % cmd]

    def _strip_addr(self, w):
        if len(w) > 1 and w[-1].startswith("@"):
            if w[-1] != "@%d" % self.unit.address:
                return None
            return w[:-1]
        return w


def main(argv):
    model = "GVE84-100"
    eeprom = None
    cosim = False
    i = 1
    while i < len(argv):
        a = argv[i]
        if a == "--model":
            model = argv[i + 1]
            i += 1
        elif a.startswith("--model="):
            model = a.split("=", 1)[1]
        elif a == "--eeprom":
            eeprom = argv[i + 1]
            i += 1
        elif a == "--cosim":
            cosim = True
        elif a in ("-h", "--help"):
            print("usage: sim.py --cosim [--model GVE84-15|GVE84-50|GVE84-100] [--eeprom FILE]")
            return 0
        else:
            print("unknown argument %s" % a, file=sys.stderr)
            return 2
        i += 1
    if model not in MODELS:
        print("unknown model %s" % model, file=sys.stderr)
        return 2
    if not cosim:
        print("only --cosim (virtual time) is implemented", file=sys.stderr)
        return 2
    sim = Cosim(model, eeprom)
    out = sys.stdout
    out.write("cosim 1 batch batch-stops\n")
    out.flush()
    for line in sys.stdin:
        line = line.rstrip("\n").rstrip("\r")
        w = line.split()
        if w and w[0] in ("quit", "exit"):
            return 0
        r = sim.handle(line)
        if r is None:
            continue
        try:
            out.write("\n".join(r) + "\n")
            out.flush()
        except BrokenPipeError:
            return 0
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
