"""The spec's motion model of a whole queue (spec 10.1, 10.2, 10.4; docs/motion-model.md),
driven by the events a host causes at known instants: vectors accepted, overrides,
HALT, GO. It answers where the axes are at any instant.

Events are fed in time order; :meth:`MotionModel.position` may then be asked about any
instant up to the last one the model was advanced to (``advance``).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

from conformance.motion.arith import axis_steps
from conformance.motion.plan import (
    Params,
    Segment,
    chain,
    cruise_rate,
    dominant,
    junction_rate,
    plan,
    rev,
)

#: XU and XD scale the captured V by these fractions (spec 10 XA/XU/XD)
EXCHANGE = {"XU": (17, 16), "XD": (15, 16)}
#: ns: the unit the manuals give T in (milliseconds), the tick a unit may dwell on
DWELL_TICK = 1_000_000


@dataclass
class Vector:
    d: tuple[int, ...]           # counter units per axis
    kind: str                    # "L" or "C"
    p: Params
    segments: list[Segment] = field(default_factory=list)   # executed, then planned
    active: bool = False         # has a plan it is executing (or dwelling before)
    start: int = 0               # the instant its current plan starts
    exit: int = 0                # the rate it leaves with
    n: int = field(init=False)   # its dominant length

    def __post_init__(self) -> None:
        self.n = dominant(self.d)

    def count(self, t: int) -> int:
        return sum(s.count(t) for s in self.segments)

    @property
    def planned(self) -> int:
        return sum(s.length for s in self.segments)

    @property
    def end(self) -> int:
        return self.segments[-1].end if self.segments else self.start

    def rate(self, t: int) -> int:
        for s in self.segments:
            if s.length and s.end > t and t >= s.t0:
                return s.rate(t)
        return 0

    def truncate(self, t: int) -> None:
        """Keep the steps done by ``t``; drop the rest of the plan."""
        self.segments = [s for s in (s.truncated(t) for s in self.segments) if s.length]

    @property
    def decision(self) -> int:
        """The instant its final braking begins (a C still joins a C pushed before)."""
        last = self.segments[-1] if self.segments else None
        return last.t0 if last is not None and last.rev else self.end


class MotionModel:
    def __init__(self, origin: list[int], xm: int = 100, *, next_brake: bool = False,
                 start_delay: int = 0) -> None:
        self.origin = list(origin)
        self.xm = xm
        self.next_brake = next_brake       # a junction at the next C's B: another reading
        #: ns every start from rest waits from the instant it became possible (a dwell
        #: before every such start, on the unit's own tick): another reading of "prodleva
        #: mezi nenavazujícími vektory" (10.2.motion.dwell bounds a start from below only)
        self.start_delay = start_delay
        self.queue: list[Vector] = []
        self.history: list[Vector] = []
        self.halted = False
        self.last_rest: int | None = None      # None: at rest long enough for any T
        self.now = 0

    # -- where the axes are ---------------------------------------------------------------
    def position(self, t: int) -> list[int]:
        pos = list(self.origin)
        for vec in self.history:
            k = vec.count(t)
            for i, x in enumerate(vec.d):
                if i < len(pos):
                    pos[i] += axis_steps(x, vec.n, k)
        return pos

    def boundaries(self, lo: int, hi: int) -> list[int]:
        """Vector end instants inside (lo, hi): where an axis may turn back."""
        return sorted({v.end for v in self.history if v.segments and lo < v.end < hi})

    @property
    def rest(self) -> int:
        """The instant the queue's motion (as far as it is planned) comes to rest."""
        return max((v.end for v in self.history if v.segments), default=self.now)

    # -- time -----------------------------------------------------------------------------
    def advance(self, t: int) -> None:
        """Let the motion run to ``t``: vectors end, the next ones start."""
        while self.queue and self.queue[0].active and self.queue[0].end <= t:
            head = self.queue[0]
            if head.planned < head.n:           # a HALT ramp ended inside it
                head.active = False
                self.last_rest = head.end
                break
            self.queue.pop(0)
            if self.queue and self.queue[0].active:     # a HALT ramp runs on into it
                continue
            at_speed = bool(head.exit) and not self.halted
            if not at_speed:
                self.last_rest = head.end
            if self.queue and not self.halted:
                self._activate(head.end, head.exit if at_speed else 0)
        self.now = max(self.now, t)

    def _activate(self, t: int, vin: int) -> None:
        """The head becomes current at ``t`` entering at ``vin``."""
        while self.queue:
            head = self.queue[0]
            if head.n - head.planned == 0:       # zero length: done at once, no dwell
                self.queue.pop(0)
                vin = 0
                continue
            if vin:
                head.start = t
            elif self.start_delay:
                head.start = max(t + self.start_delay,
                                 t if self.last_rest is None else self.last_rest + head.p.T)
            elif self.last_rest is None:
                head.start = t
            else:
                head.start = max(t, self.last_rest + head.p.T)
            head.active = True
            self._plan(head, head.start, vin)
            return

    def _plan(self, head: Vector, t: int, vin: int) -> None:
        vc = cruise_rate(head.d, head.p, self.xm)
        head.exit = self._exit(head, vc)
        head.segments += plan(t, head.n - head.planned, vin, vc, head.exit, head.p.A)

    def _exit(self, head: Vector, vc: int) -> int:
        nxt = self.queue[1] if len(self.queue) > 1 else None
        if head.kind != "C" or nxt is None or nxt.kind != "C" or nxt.n == 0:
            return 0
        vc_next = cruise_rate(nxt.d, nxt.p, self.xm)
        return junction_rate(vc, nxt.p if self.next_brake else head.p, vc_next, nxt.p.A,
                             nxt.n)

    def _replan(self, t: int) -> None:
        """Plan the head again from ``t`` (an override, or a C joining it)."""
        head = self.queue[0] if self.queue else None
        if head is None or not head.active:
            return
        if t < head.start:                       # still dwelling: keeps its start
            head.truncate(head.start - 1)
            self._plan(head, head.start, 0)
            return
        vin = head.rate(t)
        head.truncate(t)
        self._plan(head, t, vin)

    # -- what the host does ---------------------------------------------------------------
    def push(self, t: int, d: tuple[int, ...], kind: str, p: Params) -> None:
        """A vector accepted at ``t`` (L or C, counter units, captured parameters)."""
        self.advance(t)
        vec = Vector(tuple(d), kind, p)
        self.queue.append(vec)
        self.history.append(vec)
        if self.halted:
            return
        if len(self.queue) == 1:
            self._activate(t, 0)
            return
        head = self.queue[0]
        if (len(self.queue) == 2 and head.active and head.kind == "C" and kind == "C"
                and vec.n and not head.exit and t < head.decision):
            self._replan(t)

    def override(self, t: int, name: str, value: int = 0, *, modal_v: int = 0,
                 modal_a: int = 0, scales_accel: bool = False) -> None:
        """``XM value``, or ``XA``/``XU``/``XD`` on the running and queued vectors (GVE54:
        also their acceleration, ``scales_accel``)."""
        self.advance(t)
        if name == "XM":
            self.xm = value
        else:
            for vec in self.queue:
                if name == "XA":
                    p = replace(vec.p, V=modal_v, A=modal_a if scales_accel else vec.p.A)
                else:
                    num, den = EXCHANGE[name]
                    p = replace(vec.p, V=vec.p.V * num // den,
                                A=vec.p.A * num // den if scales_accel else vec.p.A)
                vec.p = p
        if not self.halted:
            self._replan(t)

    def halt(self, t: int) -> int:
        """HALT at ``t``; returns the instant the motion is at rest (H's answer)."""
        self.advance(t)
        self.halted = True
        head = self.queue[0] if self.queue else None
        if head is None or not head.active:
            return t
        if t < head.start:                        # dwelling: it does not start
            head.truncate(t)
            head.active = False
            return t
        last = head.segments[-1]
        if not head.exit and last.rev and t >= last.t0:
            return head.end                       # already braking to rest on its target
        v, a = head.rate(t), head.p.A
        for vec in self.queue:
            vec.truncate(t)
        ramp = v * v // (2 * a)
        if ramp == 0:
            head.active = False
            self.last_rest = t
            return t
        done = 0
        end = t
        for vec in self.queue:
            part = min(ramp - done, vec.n - vec.planned)
            vec.segments += chain(t, [rev(0, a, ramp, done, part)]) if part else []
            vec.active = True
            done += part
            end = vec.end
            if done == ramp:
                break
        return end

    def go(self, t: int) -> None:
        """GO at ``t``: the interrupted vector resumes from rest (with the dwell rule)."""
        self.advance(t)
        self.halted = False
        if self.queue and not self.queue[0].active:
            self._activate(t, 0)
