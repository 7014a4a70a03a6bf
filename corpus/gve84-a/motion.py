"""Motion engine of the GVE84 simulator: vector queue, trapezoidal ramps with
look-ahead braking map, stop ramps (HALT / interrupts) and the reference run (W).

All times handed in and out are integer nanoseconds of virtual time; the
kinematics inside a segment are evaluated in float seconds from the segment
start, so the same command sequence always gives the same numbers.

Units: a vector's "nominal length" D is the number of steps of its dominant
axis (VN mode) or its Euclidean length in steps (VK mode); feeds (V, B, caps)
and accelerations are expressed per that nominal unit (READINGS.md).
"""
import math

NS = 1_000_000_000
TICK_NS = 1_000_000          # the firmware's motion tick: 1 ms (READINGS.md)
EPS = 1e-9


class Vec:
    __slots__ = ("kind", "d", "lmaj", "D", "speed", "acc", "brake", "short", "vk", "s")

    def __init__(self, kind, d, speed, acc, brake, short_limit, vk):
        self.kind = kind                      # 'L' or 'C'
        self.d = tuple(d)
        self.lmaj = max(abs(c) for c in d)
        self.vk = vk
        if vk:
            self.D = math.sqrt(sum(c * c for c in d))
        else:
            self.D = float(self.lmaj)
        self.speed = float(speed)             # programmed feed (V * XM / 100)
        self.acc = float(acc)                 # nominal units / s^2
        self.brake = float(brake)             # B at the time it was queued
        self.short = self.lmaj < short_limit  # '$' rule
        self.s = 0.0                          # progress along D

    def steps_done(self, s=None):
        if s is None:
            s = self.s
        if self.D <= 0:
            return (0, 0, 0)
        s = min(max(s, 0.0), self.D)
        out = []
        for c in self.d:
            if s >= self.D:
                out.append(c)
            else:
                k = int(math.floor(abs(c) * s / self.D + EPS))
                out.append(k if c >= 0 else -k)
        return tuple(out)

    def describe(self):
        return {"kind": self.kind, "d": list(self.d), "speed": self.speed,
                "done": list(self.steps_done())}


def next_tick(t):
    return (t // TICK_NS + 1) * TICK_NS


def plan_run(v0, r, cap, a, e):
    """Phases [(duration_s, accel)] taking a vector's remaining length r from
    speed v0 to exit speed e under cruise cap and acceleration a.
    Returns (phases, v_end)."""
    if r <= EPS:
        return [], v0
    if a <= 0:
        a = 1.0
    e = min(e, cap)
    phases = []
    if v0 * v0 > e * e + 2 * a * r + 1e-6:
        # cannot brake to e any more: brake as hard as allowed all the way
        ve = math.sqrt(max(0.0, v0 * v0 - 2 * a * r))
        phases.append(((v0 - ve) / a, -a))
        return phases, ve
    if v0 > cap:
        d1 = (v0 * v0 - cap * cap) / (2 * a)
        d3 = (cap * cap - e * e) / (2 * a)
        dc = max(0.0, r - d1 - d3)
        phases.append(((v0 - cap) / a, -a))
        if dc > 0:
            phases.append((dc / cap, 0.0))
        if cap > e:
            phases.append(((cap - e) / a, -a))
        return phases, e
    vp2 = (v0 * v0 + e * e) / 2 + a * r
    vp = min(cap, math.sqrt(vp2))
    if vp < e:
        # cannot even reach e: accelerate all the way
        ve = math.sqrt(v0 * v0 + 2 * a * r)
        phases.append(((ve - v0) / a, a))
        return phases, ve
    d1 = (vp * vp - v0 * v0) / (2 * a)
    d3 = (vp * vp - e * e) / (2 * a)
    dc = max(0.0, r - d1 - d3)
    if vp > v0:
        phases.append(((vp - v0) / a, a))
    if dc > 0 and vp > 0:
        phases.append((dc / vp, 0.0))
    if vp > e:
        phases.append(((vp - e) / a, -a))
    return phases, e


def plan_stop(v0, r, a):
    """Stop ramp on the current vector. Returns (phases, stops_inside, v_end)."""
    if a <= 0:
        a = 1.0
    if v0 <= EPS:
        return [], True, 0.0
    dstop = v0 * v0 / (2 * a)
    if dstop <= r + 1e-9:
        return [(v0 / a, -a)], True, 0.0
    ve = math.sqrt(max(0.0, v0 * v0 - 2 * a * r))
    return [((v0 - ve) / a, -a)], False, ve


def eval_phases(phases, v0, tau):
    """Distance and speed tau seconds into the phases."""
    s = 0.0
    v = v0
    for dur, acc in phases:
        if tau <= 0:
            break
        dt = min(dur, tau)
        s += v * dt + 0.5 * acc * dt * dt
        v += acc * dt
        tau -= dt
    return s, max(v, 0.0)


def phases_total(phases):
    return sum(p[0] for p in phases)


def phases_dist(phases, v0):
    return eval_phases(phases, v0, phases_total(phases) + 1.0)[0]


class Motion:
    """The interpolator proper. The owning unit supplies:
       unit.fmax, unit.vl (per-axis limits), unit.T_ms, unit.inta (property),
       unit.on_stopped(t) (stop ramp finished), unit.on_ref_done(t, ok),
       unit.ref_input_active(axis), unit.rig_switch(axis) -> physical pos or None,
       unit.counter_phys() accessors below."""

    def __init__(self, unit):
        self.u = unit
        self.q = []
        self.state = "idle"        # idle | wait | run | stopping | ref
        self.t_start = None
        self.committed = [0, 0, 0]  # counters without the current vector's steps
        self.offset = [0, 0, 0]     # physical = counter + offset
        self.excursion = [[0, 0], [0, 0], [0, 0]]
        self.seg_t0 = 0
        self.seg_v0 = 0.0
        self.seg_s0 = 0.0
        self.phases = []
        self.seg_end = None         # ns of the segment's end event
        self.seg_end_kind = None    # 'vend' | 'stop'
        self.seg_v_end = 0.0
        self.ref = None
        self.ref_counter_base = None

    # ------------------------------------------------------------ queries
    def moving(self):
        """'za chodu': a vector or a stop ramp or W is in progress."""
        return self.state in ("wait", "run", "stopping", "ref")

    def running_bit(self):
        return bool(self.q) or self.state in ("run", "stopping", "ref", "wait")

    def stopping(self):
        return self.state == "stopping"

    def current_s_v(self, t):
        if self.state in ("run", "stopping") and self.q:
            ds, v = eval_phases(self.phases, self.seg_v0, (t - self.seg_t0) / NS)
            vec = self.q[0]
            return min(self.seg_s0 + ds, vec.D), v
        if self.q:
            return self.q[0].s, 0.0
        return 0.0, 0.0

    def counters(self, t):
        c = list(self.committed)
        if self.state == "ref" and self.ref is not None:
            ax = self.ref["axis"]
            c[ax] += self._ref_steps(t)
            return c
        if self.q:
            s, _ = self.current_s_v(t)
            sd = self.q[0].steps_done(s)
            for i in range(3):
                c[i] += sd[i]
        return c

    def physical(self, t):
        c = self.counters(t)
        return [self.u.dir_sign(i) * c[i] + self.offset[i] for i in range(3)]

    def track(self, t):
        p = self.physical(t)
        for i in range(3):
            lo, hi = self.excursion[i]
            self.excursion[i] = [min(lo, p[i]), max(hi, p[i])]

    # ------------------------------------------------------------ counters
    def set_counter(self, t, axis, value):
        """N / NX / W zeroing / reset: counter changes, the axis does not."""
        c = self.counters(t)
        sg = self.u.dir_sign(axis)
        phys = sg * c[axis] + self.offset[axis]
        delta = value - c[axis]
        self.committed[axis] += delta
        self.offset[axis] = phys - sg * value

    # ------------------------------------------------------------ queue ops
    def caps(self):
        u = self.u
        out = []
        for v in self.q:
            cap = v.speed
            if v.lmaj > 0 and v.D > 0:
                cap = min(cap, u.fmax * v.D / v.lmaj)
                for i in range(3):
                    if v.d[i]:
                        cap = min(cap, u.vl[i] * v.D / abs(v.d[i]))
            if v.short:
                cap = min(cap, v.brake)
            out.append(max(cap, 1.0))
        return out

    def exits(self, caps):
        q = self.q
        n = len(q)
        ex = [0.0] * n
        for i in range(n - 1, -1, -1):
            if i == n - 1:
                e = 0.0
            else:
                nxt = q[i + 1]
                if q[i].kind == "C" and nxt.kind == "C":
                    e = min(q[i].brake, caps[i], caps[i + 1])
                    rem = nxt.D - nxt.s
                    e = min(e, math.sqrt(ex[i + 1] ** 2 + 2 * nxt.acc * rem))
                else:
                    e = 0.0
            ex[i] = e
        return ex

    def push(self, t, vec):
        self.q.append(vec)
        if self.state == "run":
            self.replan(t)
        self.kick(t)

    def kick(self, t):
        """Start the queue from standstill if allowed."""
        if self.state == "idle" and self.q and not self.u.inta:
            self.state = "wait"
            self.t_start = next_tick(t) + self.u.T_ms * TICK_NS

    def replan(self, t):
        if self.state != "run" or not self.q:
            return
        s, v = self.current_s_v(t)
        self._begin_run(t, s, v)

    def _begin_run(self, t, s, v):
        vec = self.q[0]
        vec.s = s
        caps = self.caps()
        ex = self.exits(caps)
        phases, ve = plan_run(v, vec.D - s, caps[0], vec.acc, ex[0])
        self.state = "run"
        self.seg_t0 = t
        self.seg_s0 = s
        self.seg_v0 = v
        self.phases = phases
        self.seg_end = t + int(round(phases_total(phases) * NS))
        self.seg_end_kind = "vend"
        self.seg_v_end = ve if ex[0] > 0 else 0.0

    def _begin_stop(self, t, s, v):
        vec = self.q[0]
        vec.s = s
        phases, inside, ve = plan_stop(v, vec.D - s, vec.acc)
        self.state = "stopping"
        self.seg_t0 = t
        self.seg_s0 = s
        self.seg_v0 = v
        self.phases = phases
        self.seg_end = t + int(round(phases_total(phases) * NS))
        self.seg_end_kind = "stop" if inside else "vend"
        self.seg_v_end = ve

    def halt(self, t):
        """Request a stop ramp (H, interrupt, INTA written). Returns True when
        a ramp is in progress (the answer of H falls due at its end)."""
        if self.state == "run":
            s, v = self.current_s_v(t)
            self.track(t)
            self._begin_stop(t, s, v)
            return True
        if self.state == "wait":
            self.state = "idle"
            self.t_start = None
            return False
        if self.state == "stopping":
            return True
        return False

    def resume(self, t):
        self.kick(t)

    def delete_all(self, t):
        if self.q:
            sd = self.q[0].steps_done()
            for i in range(3):
                self.committed[i] += sd[i]
        self.q = []
        if self.state == "wait":
            self.state = "idle"

    def take_queue(self, t):
        """KEEP: detach the queue (the current vector keeps its progress)."""
        q = self.q
        if q:
            sd = q[0].steps_done()
            for i in range(3):
                self.committed[i] += sd[i]
        self.q = []
        if self.state == "wait":
            self.state = "idle"
        return q

    def give_queue(self, t, q):
        """RESTORE."""
        self.q = q
        if q:
            sd = q[0].steps_done()
            for i in range(3):
                self.committed[i] -= sd[i]

    def stop_dead(self, t):
        """Power loss / reset: the pulses stop where they are."""
        self.track(t)
        c = self.counters(t)
        self.committed = list(c)
        self.q = []
        self.state = "idle"
        self.t_start = None
        self.ref = None

    # ------------------------------------------------------------ reference run
    def start_ref(self, t, axis, n2, n3, n4, n5):
        self.ref = {"axis": axis, "dir": 1 if n2 > 0 else -1, "max1": abs(n2),
                    "r1": n3, "max2": n4, "r2": n5, "phase": 0, "t0": None,
                    "base": 0, "end": None, "hit": None}
        self.state = "ref"
        self.t_start = next_tick(t) + self.u.T_ms * TICK_NS
        self.ref["end"] = self.t_start

    def _ref_steps(self, t):
        r = self.ref
        if r["phase"] == 0:
            return r["base"]
        rate = r["r1"] if r["phase"] == 1 else r["r2"]
        lim = r["lim"]
        k = int(math.floor((t - r["t0"]) * rate / NS + EPS)) if t >= r["t0"] else 0
        k = min(k, lim)
        d = r["dir"] if r["phase"] == 1 else -r["dir"]
        return r["base"] + d * k

    def _ref_phase(self, t, phase):
        r = self.ref
        ax = r["axis"]
        r["base"] = self._ref_steps(t) if r["phase"] else 0
        r["phase"] = phase
        r["t0"] = t
        rate = r["r1"] if phase == 1 else r["r2"]
        d = r["dir"] if phase == 1 else -r["dir"]
        sg = self.u.dir_sign(ax)
        here = sg * (self.committed[ax] + r["base"]) + self.offset[ax]
        sw = self.u.rig_switch(ax)
        lim = r["max1"] if phase == 1 else r["max2"]
        if phase == 1:
            if sw is not None:
                k = (sw - here) * d * sg
                r["hit"] = k if 0 <= k <= lim else None
            else:
                r["hit"] = 0 if self.u.ref_input_active(ax) else None
        else:
            if sw is not None:
                r["hit"] = 1 if lim >= 1 else None     # released one step back
            else:
                r["hit"] = 0 if not self.u.ref_input_active(ax) else None
        k = r["hit"] if r["hit"] is not None else lim
        r["lim"] = k
        r["end"] = t + (int(math.ceil(k * NS / rate)) if k else 0)

    def ref_input_changed(self, t):
        """The reference input of the W axis changed level (no rig switch)."""
        r = self.ref
        if self.state != "ref" or r is None or r["phase"] == 0:
            return
        ax = r["axis"]
        if self.u.rig_switch(ax) is not None:
            return
        active = self.u.ref_input_active(ax)
        if (r["phase"] == 1 and active) or (r["phase"] == 2 and not active):
            k = self._ref_steps(t) - r["base"]
            r["lim"] = abs(k)
            r["hit"] = abs(k)
            r["end"] = t

    def _ref_event(self, t):
        r = self.ref
        if r["phase"] == 0:
            self._ref_phase(t, 1)
            return
        found = r["hit"] is not None
        if r["phase"] == 1 and found:
            self.track(t)
            self._ref_phase(t, 2)
            return
        # finished (released, or a travel exhausted)
        ax = r["axis"]
        steps = self._ref_steps(t)
        self.committed[ax] += steps
        self.ref = None
        self.state = "idle"
        self.track(t)
        ok = r["phase"] == 2 and found
        if ok:
            self.set_counter(t, ax, 0)
        self.u.on_ref_done(t, ok)

    # ------------------------------------------------------------ events
    def next_event(self):
        if self.state == "wait":
            return self.t_start
        if self.state in ("run", "stopping"):
            return self.seg_end
        if self.state == "ref":
            return self.ref["end"]
        return None

    def on_event(self, t):
        st = self.state
        if st == "wait":
            self.state = "idle"
            if not self.q:
                return
            self._begin_run(t, self.q[0].s, 0.0)
            return
        if st == "ref":
            self._ref_event(t)
            return
        if st not in ("run", "stopping"):
            return
        vec = self.q[0]
        if self.seg_end_kind == "stop":
            ds = phases_dist(self.phases, self.seg_v0)
            vec.s = min(self.seg_s0 + ds, vec.D)
            if vec.s >= vec.D - 1e-7:
                vec.s = vec.D
                self._pop(t)
            self.state = "idle"
            self.track(t)
            self.u.on_stopped(t)
            self.kick(t)            # only if INTA was cleared meanwhile (SW6)
            return
        # the current vector ends
        ve = self.seg_v_end
        vec.s = vec.D
        self.track(t)
        self._pop(t)
        if st == "stopping":
            if self.q and ve > EPS:
                self._begin_stop(t, 0.0, ve)
                return
            self.state = "idle"
            self.u.on_stopped(t)
            self.kick(t)
            return
        if self.q and ve > EPS:
            self._begin_run(t, 0.0, ve)
            return
        self.state = "idle"
        self.kick(t)

    def _pop(self, t):
        vec = self.q.pop(0)
        for i in range(3):
            self.committed[i] += vec.d[i]
