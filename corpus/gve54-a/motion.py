"""GVE54 interpolator motion model: the vector queue and the step generator.

Everything runs in virtual time (integer nanoseconds).  The interpolator
steps the dominant axis of the executing vector one pulse at a time; the
minor axes follow by rounded linear interpolation (Bresenham).  Speeds are
in pulses/s of the vector's own micro-step mode, accelerations in
pulses/s^2.  Counters and physical positions are in 1/16 steps.

Between two pulses the speed changes with constant acceleration, so the
time between the pulse at speed v and the next one at speed v' is
2/(v+v').  The speed chosen for every pulse is the highest that
  * does not exceed the vector's top speed (V, or min(V,B) for a short
    vector) by more than one step of deceleration,
  * grows by at most one step of acceleration (v'^2 <= v^2 + 2A),
  * still lets the axis brake to the end speed of the vector within the
    pulses that remain (v'^2 <= ve^2 + 2A(r-1)).
The end speed of a vector comes from a backward pass over the queue
(READINGS.md): B of the vector when another vector follows, 0 otherwise.
"""

import copy
import math

QUEUE_CAPACITY = 96
AXES = 3


class Vector:
    __slots__ = ("d", "n", "P", "V", "A", "B", "short", "cont", "T", "done")

    def __init__(self, d, P, V, A, B, short_limit, cont, T):
        self.d = list(d)                      # pulses per axis (signed)
        self.n = max(abs(c) for c in d)       # dominant axis length, pulses
        self.P = P                            # counter units per pulse (16/microsteps)
        self.V = V                            # top speed, pulses/s
        self.A = A                            # acceleration, pulses/s^2
        self.B = B                            # brake speed towards a following vector
        self.short = self.n < short_limit     # "short vektory jsou mensi nez $"
        self.cont = cont                      # C (True) or L (False)
        self.T = T                            # dwell after it (ms) when it ends at rest
        self.done = 0                         # pulses of the dominant axis done

    @property
    def vmax(self):
        return min(self.V, self.B) if self.short else self.V

    def clone(self):
        v = Vector.__new__(Vector)
        for s in Vector.__slots__:
            setattr(v, s, getattr(self, s))
        v.d = list(self.d)
        return v


class Motion:
    def __init__(self):
        self.pos = [0] * AXES            # position counters (what PF reads)
        self.phys = [0] * AXES           # where the axes really are
        self.exc = [[0, 0] for _ in range(AXES)]
        self.queue = []
        self.active = False              # the interpolator executes the queue
        self.stopping = False            # a stop ramp (H, interrupt) is in progress
        self.v = 0.0                     # speed at the last pulse
        self.next_t = None               # instant of the next pulse
        self.next_v = 0.0                # speed at that pulse
        self.last_stop_step = False      # the next pulse ends the stop ramp
        self.dwell_until = None          # T dwell after the queue ran out
        self._ve = None                  # cached end speed of queue[0]

    # ------------------------------------------------------------ status
    def busy(self):
        """'za chodu': pulses are being generated, a stop ramp or a dwell runs."""
        return self.active or self.dwell_until is not None

    def full(self):
        return len(self.queue) >= QUEUE_CAPACITY

    def invalidate(self):
        self._ve = None

    # ------------------------------------------------------------ control
    def add(self, vec):
        self.queue.append(vec)
        self._ve = None

    def start(self, now):
        """Begin (or resume) executing the queue from rest at instant now."""
        self._skip_zero()
        if not self.queue:
            return False
        self.active = True
        self.stopping = False
        self.v = 0.0
        self._schedule(now)
        return True

    def request_stop(self, now):
        """Brake along the path (ramp with A).  Returns True if stopped at once."""
        if not self.active:
            return False
        if self.v <= 0.0:
            # no pulse made since the start: stop where we stand
            self._rest()
            return True
        if not self.stopping:
            self.stopping = True
            # the pulse already timed keeps its instant; decide it again so a
            # ramp that would end on it is noticed
            self.last_stop_step = self.next_v <= 0.0
        return False

    def hard_stop(self):
        """Power loss / reset: pulses cease immediately, queue lost."""
        self.queue = []
        self._rest()
        self.dwell_until = None
        self._ve = None

    def _rest(self):
        self.active = False
        self.stopping = False
        self.v = 0.0
        self.next_t = None
        self.next_v = 0.0
        self.last_stop_step = False

    def _skip_zero(self):
        while self.queue and self.queue[0].n - self.queue[0].done <= 0:
            self.queue.pop(0)
            self._ve = None

    # ------------------------------------------------------------ planning
    def _end_speed(self):
        if self._ve is None:
            q = self.queue
            e = 0.0
            for i in range(len(q) - 1, 0, -1):
                nx, cur = q[i], q[i - 1]
                cap = math.sqrt(e * e + 2.0 * nx.A * (nx.n - nx.done))
                e = min(float(cur.B), float(cur.vmax), float(nx.vmax), cap)
            self._ve = e
        return self._ve

    def _schedule(self, t):
        vec = self.queue[0]
        A = float(vec.A)
        v = self.v
        r = vec.n - vec.done
        ve = self._end_speed()
        vmax = float(vec.vmax)
        two_a = 2.0 * A
        if v < vmax:
            cand2 = min(vmax * vmax, v * v + two_a)
        elif v > vmax:
            cand2 = max(vmax * vmax, v * v - two_a)
        else:
            cand2 = v * v
        lim2 = ve * ve + two_a * (r - 1)
        v2 = max(min(cand2, lim2), v * v - two_a)
        if self.stopping:
            v2 = min(v2, v * v - two_a)
        if v2 < 1e-6 * two_a:
            v2 = 0.0                          # rounding: a ramp that ends, ends
        nv = math.sqrt(v2)
        self.last_stop_step = self.stopping and nv <= 0.0
        s = v + nv
        if s <= 0.0:
            # one pulse from rest to rest: half accelerating, half braking
            dt = 2.0e9 / math.sqrt(A)
        else:
            dt = 2.0e9 / s
        self.next_t = t + max(1, int(round(dt)))
        self.next_v = nv

    # ------------------------------------------------------------ stepping
    def _pulse(self):
        vec = self.queue[0]
        k = vec.done + 1
        n = vec.n
        for a in range(AXES):
            c = vec.d[a]
            if c == 0:
                continue
            m = abs(c)
            delta = (2 * k * m + n) // (2 * n) - (2 * (k - 1) * m + n) // (2 * n)
            if delta:
                s = vec.P * delta * (1 if c > 0 else -1)
                self.pos[a] += s
                p = self.phys[a] + s
                self.phys[a] = p
                e = self.exc[a]
                if p < e[0]:
                    e[0] = p
                elif p > e[1]:
                    e[1] = p
        vec.done = k

    def run_until(self, limit):
        """Run pulses with instants <= limit.  Returns (kind, t) right after the
        first event that changes what F / SR6 read, or None.  kinds:
        'vector_end', 'finished' (queue ran out), 'stopped' (stop ramp ended),
        'dwell_end'."""
        if self.dwell_until is not None and not self.active:
            if self.dwell_until <= limit:
                t = self.dwell_until
                self.dwell_until = None
                return ("dwell_end", t)
            return None
        while self.active and self.next_t is not None and self.next_t <= limit:
            t = self.next_t
            self._pulse()
            self.v = self.next_v
            stop_here = self.last_stop_step
            vec = self.queue[0]
            ended = False
            if vec.done >= vec.n:
                self.queue.pop(0)
                self._ve = None
                self._skip_zero()
                ended = True
            if stop_here:
                self._rest()
                return ("stopped", t)
            if not self.queue:
                was_stopping = self.stopping
                self._rest()
                if was_stopping:
                    return ("stopped", t)
                if vec.T > 0:
                    self.dwell_until = t + vec.T * 1_000_000
                return ("finished", t)
            self._schedule(t)
            if ended:
                return ("vector_end", t)
        return None

    def peek_event(self):
        """Instant of the next event run_until would report (None: none)."""
        if not self.active:
            return self.dwell_until
        m = copy.copy(self)
        m.pos = list(self.pos)
        m.phys = list(self.phys)
        m.exc = [list(e) for e in self.exc]
        m.queue = [v.clone() for v in self.queue]
        ev = m.run_until(float("inf"))
        return None if ev is None else ev[1]

    # ------------------------------------------------------------ queue edits
    def exchange(self, fn):
        for vec in self.queue:
            fn(vec)
        self._ve = None

    def snapshot_queue(self):
        return [v.clone() for v in self.queue]
