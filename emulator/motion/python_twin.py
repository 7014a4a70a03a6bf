"""The pure-Python stepper core: the readable reference the C core is checked against.

The queue holds *entries*: an accepted vector with the steps of it already done. The
head entry is the executing one; it has a plan (a list of segments, see segment.py)
from the instant it starts. Nothing iterates over steps: advancing retires whole
entries at their end instants; positions and pulse instants are closed form.

Every replacement of a plan (override, junction, HALT) happens at an instant ``t``:
the steps done by then are kept, the new plan starts at ``t`` from the rate the old one
had there. Executed pieces of plans are kept in a bounded history for :meth:`pulses`.
"""

from __future__ import annotations

import copy
from collections import deque
from dataclasses import dataclass, replace
from math import isqrt

import emulator.motion.segment as seg
from emulator.motion.arith import NEVER, axis_count, first_step_reaching, stop_distance
from emulator.motion.interface import Deviation, KeepSave, MotionFlags, Vector

#: executed plan pieces kept for pulses() of the past
HISTORY = 65536


@dataclass
class Entry:
    vector: Vector
    n: int                          # dominant length
    done: int = 0                   # steps done before the current plan
    plan: list | None = None        # segments; None: not started
    end: int = 0                    # instant of the plan's last step
    exit_rate: int = 0              # rate at the end of the plan
    decision: int = -1              # a following C may still join before this instant
    final: bool = True              # the plan ends the vector (False: a HALT ramp ends in it)

    def steps(self, t: int) -> int:
        if self.plan is None:
            return self.done
        return self.done + sum(seg.count(s, t) for s in self.plan)

    def rate(self, t: int) -> int:
        if not self.plan or t < self.plan[0].start:
            return 0
        for s in self.plan:
            if t < s.end:
                return seg.rate(s, t)
        return self.exit_rate


def _length(steps: tuple[int, ...]) -> int:
    return max((abs(d) for d in steps), default=0)


@dataclass(frozen=True)
class Piece:
    """An executed stretch of a vector's plan: steps (k_from, k_to] at their instants."""
    base: tuple[int, ...]
    steps: tuple[int, ...]
    n: int
    k_from: int
    k_to: int
    plan: tuple


class PythonMotion:
    """The Motion protocol (interface.py) in pure Python."""

    kind = "python"

    def __init__(self, axes: int, max_rate: int, deviations: Deviation = Deviation.NONE) -> None:
        self.axes = axes
        self.max_rate = max_rate
        self.deviations = Deviation(deviations)
        self._now = 0
        self._queue: deque[Entry] = deque()
        self._base = [0] * axes          # position at the head vector's start
        self._halted = False
        self._rest = 0                   # when the last stop ended (dwell reference)
        self._after_c = False            # that stop ended a C of non-zero length, no more
        self._stop_end = 0               # the end of a HALT ramp
        self._xm = 100
        self._history: deque[Piece] = deque(maxlen=HISTORY)
        self._offset = [0] * axes        # physical position minus counter, per axis
        self._lo = [0] * axes            # the physical extremes visited so far
        self._hi = [0] * axes

    # -- planning -----------------------------------------------------------------
    def _cruise(self, e: Entry) -> int:
        vec, n = e.vector, e.n
        v = vec.velocity * self._xm // 100
        if vec.path_speed:
            s = sum(d * d for d in vec.steps[:3])
            if s:
                v = isqrt((v * n) ** 2 // s)
        if n < vec.short:
            v = min(v, vec.brake)
        v = min(v, self.max_rate)
        for d, cap in zip(vec.steps, vec.axis_limits, strict=True):
            if d:
                v = min(v, cap * n // abs(d))
        return max(v, 1)

    def _junction(self, e: Entry, nxt: Entry | None, vc: int) -> int:
        """The exit rate into a following C (0 when there is none). A zero-length C
        carries no speed: the C after it starts from rest."""
        if nxt is None or not (e.vector.continuous and nxt.vector.continuous) or nxt.n == 0:
            return 0
        if e.n == 0 and not self.deviations & Deviation.ZERO_LENGTH_JUNCTION:
            return 0
        if self.deviations & Deviation.JUNCTION_STOPS:
            return 0
        if self.deviations & Deviation.REVERSAL_STOPS and any(
                a * b < 0 for a, b in zip(e.vector.steps, nxt.vector.steps, strict=True)):
            return 0
        brake = nxt.vector.brake if self.deviations & Deviation.NEXT_BRAKE else e.vector.brake
        if self.deviations & Deviation.JUNCTION_UNBRAKED:
            brake = vc
        return max(0, min(brake, vc, self._cruise(nxt), isqrt(2 * nxt.vector.accel * nxt.n)))

    def _plan(self, e: Entry, t: int, vin: int, join: bool) -> None:
        """Plan the rest of ``e`` from ``t`` at rate ``vin``."""
        vc = self._cruise(e)
        nxt = self._queue[1] if len(self._queue) > 1 else None
        vx = self._junction(e, nxt, vc) if join else 0
        e.plan = seg.plan(t, e.done, e.n - e.done, vin, vc, vx, e.vector.accel)
        e.end = e.plan[-1].end if e.plan else t
        e.exit_rate = vx
        e.final = True
        # a C that will stop may still join a C pushed before its final braking begins
        # (or, when braking takes no whole step, before its last step)
        e.decision = -1
        if vx == 0 and e.vector.continuous:
            last = e.plan[-1] if e.plan else None
            if last is None:
                e.decision = t
            elif last.kind == seg.REV:
                e.decision = last.start
            else:
                e.decision = t if self.deviations & Deviation.CONTINUOUS_DWELL else last.end

    def _start_head(self, t: int, vin: int) -> None:
        e = self._queue[0]
        if e.plan is not None:        # a piece of a HALT ramp already planned
            return
        # a junction, L0,0,0, or a C right after a C that stopped starts at once; any
        # other start from rest waits out the dwell
        at_once = vin > 0 or e.done == e.n or (e.vector.continuous and self._after_c)
        start = t if at_once else max(t, self._rest + e.vector.dwell)
        self._plan(e, start, vin, join=True)

    def _replan(self, t: int, join: bool) -> None:
        """Plan the head again from ``t`` (an override, or a C joining)."""
        if not self._queue or self._halted:
            return
        e = self._queue[0]
        if not e.plan or not e.final:
            return
        join = join and (e.exit_rate > 0 or e.decision > t)
        if t < e.plan[0].start:              # still dwelling: the same start, a new plan
            self._plan(e, e.plan[0].start, 0, join)
            return
        k = e.steps(t)
        v = e.rate(t)
        self._record(e, k)
        e.done = k
        self._plan(e, t, v, join)

    def _record(self, e: Entry, k_to: int) -> None:
        if e.plan and k_to > e.done:
            self._history.append(Piece(tuple(self._base), e.vector.steps, e.n, e.done, k_to,
                                       tuple(e.plan)))

    def _visit(self, counters) -> None:
        """Record a point the axes have been at (counter units) in the excursion."""
        for i, c in enumerate(counters):
            x = c + self._offset[i]
            if x < self._lo[i]:
                self._lo[i] = x
            elif x > self._hi[i]:
                self._hi[i] = x

    # -- time -----------------------------------------------------------------------
    @property
    def now(self) -> int:
        return self._now

    def advance(self, t: int) -> None:
        if t < self._now:
            t = self._now
        q = self._queue
        while q:
            e = q[0]
            if e.plan is None:
                if self._halted:
                    break
                self._start_head(self._now, 0)
            if e.end > t:
                break
            self._record(e, e.steps(e.end))
            if not e.final:                  # a HALT ramp ended inside this vector
                e.done = e.steps(e.end)
                e.plan = None
                self._rest = e.end
                self._after_c = False
                self._visit(self._position_at(e))
                if self._halted:
                    break
                self._start_head(e.end, 0)
                continue
            q.popleft()
            for i, d in enumerate(e.vector.steps):
                self._base[i] += d
            self._visit(self._base)
            if not e.n:
                self._after_c = False
            elif e.exit_rate == 0:
                self._rest = e.end
                self._after_c = (e.vector.continuous and not self._halted
                                 and not self.deviations & Deviation.CONTINUOUS_DWELL)
            if q and (not self._halted or q[0].plan is not None):
                self._start_head(e.end, e.exit_rate)
        self._now = t

    def next_event(self) -> int | None:
        if self._queue:
            e = self._queue[0]
            if e.plan is not None and e.end > self._now:
                return e.end
        if self._halted and self._stop_end > self._now:
            return self._stop_end
        return None

    def drain_instant(self) -> int | None:
        if self._halted or not self._queue:
            return None
        ghost = self._ghost()
        ghost.advance(NEVER)
        return ghost._rest if not ghost._queue else None

    # -- queries --------------------------------------------------------------------
    def position(self, t: int) -> tuple[int, ...]:
        self.advance(t)
        return self._position_now()

    def _position_now(self) -> tuple[int, ...]:
        if not self._queue:
            return tuple(self._base)
        return self._position_at(self._queue[0])

    def _position_at(self, e: Entry) -> tuple[int, ...]:
        """The counters with the head ``e`` at its steps done by now."""
        k = e.steps(self._now)
        steps = e.vector.steps
        return tuple(b + axis_count(k, d, e.n) for b, d in zip(self._base, steps, strict=True))

    def physical(self, t: int) -> tuple[int, ...]:
        return tuple(c + o for c, o in zip(self.position(t), self._offset, strict=True))

    def excursion(self, t: int) -> tuple[tuple[int, int], ...]:
        self._visit(self.position(t))
        return tuple(zip(self._lo, self._hi, strict=True))

    def flags(self, t: int) -> MotionFlags:
        self.advance(t)
        stopping = self._halted and self._stop_end > self._now
        busy = bool(self._queue)
        return MotionFlags(busy=busy, moving=(busy and not self._halted) or stopping,
                           stopping=stopping, halted=self._halted)

    def queued(self, t: int) -> int:
        self.advance(t)
        return len(self._queue)

    def instant_of_position(self, axis: int, value: int) -> int | None:
        if self._position_now()[axis] == value:
            return self._now
        for p in self._timeline(NEVER):
            d = p.steps[axis]
            c = value - p.base[axis]
            if d == 0 or c == 0 or (c > 0) != (d > 0) or abs(c) > abs(d):
                continue
            k = max(first_step_reaching(abs(c), d, p.n), p.k_from + 1)
            if k <= p.k_to and p.base[axis] + axis_count(k, d, p.n) == value:
                t = _step_instant(p, k)
                if t >= self._now:
                    return t
        return None

    def pulses(self, t0: int, t1: int):
        times: list[int] = []
        masks: list[int] = []
        for p in self._timeline(t1):
            first = max(p.k_from, _plan_steps(p.plan, t0 - 1)) + 1
            last = min(p.k_to, _plan_steps(p.plan, t1 - 1))
            for k in range(first, last + 1):
                mask = 0
                for i, d in enumerate(p.steps):
                    if axis_count(k, d, p.n) != axis_count(k - 1, d, p.n):
                        mask |= (1 << i) | ((d < 0) << (4 + i))
                times.append(_step_instant(p, k))
                masks.append(mask)
        # only pulse trains need numpy: a unit (a co-simulator's) starts without it
        import numpy as np

        return np.array(times, dtype=np.int64), np.array(masks, dtype=np.uint8)

    def _ghost(self) -> PythonMotion:
        """A copy to play the deterministic future on (without the history)."""
        history, self._history = self._history, deque(maxlen=HISTORY)
        try:
            return copy.deepcopy(self)
        finally:
            self._history = history

    def _timeline(self, t1: int) -> list[Piece]:
        """Executed pieces, then the planned future up to ``t1`` (played on a ghost)."""
        pieces = list(self._history)
        ghost = self._ghost()
        ghost.advance(t1)
        pieces.extend(ghost._history)
        if ghost._queue and ghost._queue[0].plan:
            e = ghost._queue[0]
            pieces.append(Piece(tuple(ghost._base), e.vector.steps, e.n, e.done,
                                e.steps(NEVER), tuple(e.plan)))
        return pieces

    # -- commands -------------------------------------------------------------------
    def push(self, vector: Vector, t: int) -> None:
        self.advance(t)
        e = Entry(vector, _length(vector.steps))
        q = self._queue
        q.append(e)
        if len(q) == 1:
            if not self._halted:
                self._start_head(t, 0)
                self.advance(t)           # a zero-length vector completes at once
        elif len(q) == 2 and q[0].decision > t and vector.continuous:
            self._replan(t, join=True)

    def halt(self, t: int) -> int:
        self.advance(t)
        self._visit(self._position_now())
        if self._halted:
            return max(self._stop_end, t)
        self._halted = True
        self._after_c = False
        self._stop_end = t
        q = self._queue
        if not q or q[0].plan is None:
            return t
        head = q[0]
        if t < head.plan[0].start:            # still dwelling: not started after all
            head.plan = None
            return t
        last = head.plan[-1]
        if (head.exit_rate == 0 and last.kind == seg.REV and t >= last.start
                and not self.deviations & (Deviation.HALT_SHORT | Deviation.HALT_DEAD)):
            # already braking to rest on its target: that ramp is the stop
            self._stop_end = head.end
            return head.end
        k = head.steps(t)
        v = head.rate(t)
        a = head.vector.accel
        distance = 0 if self.deviations & Deviation.HALT_DEAD else stop_distance(v, a)
        self._record(head, k)
        head.done = k
        # one braking curve from t, run on through as many vectors as it needs
        covered = 0
        start = t
        for e in q:
            if covered == distance:
                break
            length = min(distance - covered, e.n - e.done)
            piece = seg.reverse(t, 0, a, distance, covered, length, e.done)
            e.plan = [piece] if length else []
            e.end = piece.end if length else start
            e.exit_rate = 0
            e.decision = -1
            covered += length
            e.final = e.done + length == e.n
            start = e.end
        if covered == 0:
            head.plan = None
            self._rest = t
            return t
        self._stop_end = start
        return start

    def resume(self, t: int) -> None:
        self.advance(t)
        if not self._halted:
            return
        self._halted = False
        if self._queue and self._queue[0].plan is None:
            head = self._queue[0]
            at_speed = self.deviations & Deviation.GO_AT_SPEED and head.done < head.n
            self._start_head(t, self._cruise(head) if at_speed else 0)

    def clear(self, t: int) -> None:
        self.advance(t)
        self._base = list(self._position_now())
        self._visit(self._base)
        self._queue.clear()
        self._halted = False
        self._after_c = False

    def keep(self, t: int) -> KeepSave:
        self.advance(t)
        saved = KeepSave(tuple((e.vector, e.done) for e in self._queue), self._halted)
        self._base = list(self._position_now())
        self._visit(self._base)
        self._queue.clear()
        self._halted = False
        self._after_c = False
        return saved

    def restore(self, saved: KeepSave, t: int) -> None:
        self.advance(t)
        here = self._position_now()
        self._visit(here)
        self._queue = deque(Entry(v, _length(v.steps), done) for v, done in saved.entries)
        self._halted = halted = saved.halted
        self._after_c = False
        if self._queue:
            head = self._queue[0]
            self._base = [p - axis_count(head.done, d, head.n)
                          for p, d in zip(here, head.vector.steps, strict=True)]
            if not halted:
                self._start_head(t, 0)
        else:
            self._base = list(here)

    def set_position(self, axis: int, value: int, t: int) -> None:
        self.advance(t)
        here = self._position_now()
        self._visit(here)
        self._base[axis] += value - here[axis]
        self._offset[axis] -= value - here[axis]      # the axis itself does not move

    def jump(self, axis: int, delta: int, t: int) -> None:
        self.advance(t)
        self._visit(self._position_now())
        self._base[axis] += delta
        self._visit(self._position_now())

    def _modify(self, change, t: int) -> None:
        self.advance(t)
        for e in self._queue:
            e.vector = change(e.vector)
        self._replan(t, join=True)

    def set_velocity(self, velocity: int, t: int, accel: int | None = None) -> None:
        def change(v: Vector) -> Vector:
            return replace(v, velocity=velocity, accel=v.accel if accel is None else accel)
        self._modify(change, t)

    def scale_velocity(self, num: int, den: int, t: int, accel: bool = False) -> None:
        def change(v: Vector) -> Vector:
            return replace(v, velocity=max(1, v.velocity * num // den),
                           accel=max(1, v.accel * num // den) if accel else v.accel)
        self._modify(change, t)

    def set_multiplier(self, percent: int, t: int) -> None:
        self.advance(t)
        self._xm = percent
        self._replan(t, join=True)


def _plan_steps(plan: tuple, t: int) -> int:
    """The vector's steps done at ``t`` under ``plan``."""
    return plan[0].k0 + sum(seg.count(s, t) for s in plan) if plan else 0


def _step_instant(p: Piece, k: int) -> int:
    for s in p.plan:
        if s.k0 < k <= s.k0 + s.length:
            return seg.step_instant(s, k - s.k0)
    raise ValueError(f"step {k} is not in the plan")


