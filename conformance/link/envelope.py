"""The motion envelope of a run: where each axis may physically be, in
counter units from where the run began, kept from the frames the unit accepted.

Pure bookkeeping, no I/O. Every axis is a :class:`Span` (an interval: a position known
exactly is a span of one point). A vector the unit may have accepted counts with its
whole length until the unit has shown it ended (spec 10.1, 10.4, 10.5): the queue of
one axis is kept as its total and its extreme prefix sums (:class:`Path`), so a queue of
back-and-forth vectors costs its widest swing, not the sum of its lengths. A halted
remainder counts whole. A kept one (`K`) is kept as where its run may take each axis:
the places the queue could still visit when it was kept, carried along by every move
the axes make until `R` gives it back, so that a read which tells how far the queue had
got before `K` never makes the remainder count from the wrong place.

`N`, `N<axis>`, `J` and `W` move the counters, not the axes: they change the offset
between a counter and the physical position, which is how a position read (`PF`, `P`)
taken while nothing can move tells where the axes are.

Each event takes an :class:`Outcome`: what the answer says happened. ``UNCLEAR`` (no
answer, or bytes that are not one) assumes whichever of "done" and "not done" reaches
farther, so the bookkeeping never underestimates where an axis can be; the guard judges
a frame before it is sent by applying its event as ``UNCLEAR`` to a copy.

The counters are not the axes: a unit that restarts by itself (a brown-out, a watchdog
reset) comes back with its counters at 0 (spec 9) wherever its axes stopped. So the
envelope keeps the *trail* of each axis, every place it may have been since a read at
rest last agreed with the frames, and a read that could be a restart's (:meth:`observe`)
puts the axis anywhere on that trail, its counter counting from there.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Callable, Sequence
from typing import NamedTuple

INF = math.inf
#: a named tuple made at C speed (the class's own ``__new__`` is Python): the guard makes
#: thousands of spans a second
_new = tuple.__new__


class Span(NamedTuple):
    """An interval of positions (or of offsets, or of factors); bounds may be infinite.
    (A named tuple: the guard makes and compares thousands of them a second.)"""

    lo: float
    hi: float

    def __add__(self, other: Span) -> Span:  # type: ignore[override]
        return _new(Span, (self.lo + other.lo, self.hi + other.hi))

    def __sub__(self, other: Span) -> Span:
        return Span(self.lo - other.hi, self.hi - other.lo)

    def times(self, factor: Span) -> Span:
        if factor.lo == factor.hi == 1:
            return self
        ends = [a * b for a in (self.lo, self.hi) for b in (factor.lo, factor.hi)
                if not (math.isinf(a) and b == 0)]
        return Span(min(ends), max(ends))

    def hull(self, other: Span) -> Span:
        lo, hi = self.lo, self.hi
        if other.lo < lo:
            lo = other.lo
        if other.hi > hi:
            hi = other.hi
        return self if lo == self.lo and hi == self.hi else _new(Span, (lo, hi))

    def meet(self, other: Span) -> Span | None:
        lo, hi = max(self.lo, other.lo), min(self.hi, other.hi)
        return Span(lo, hi) if lo <= hi else None

    @property
    def exact(self) -> bool:
        return self.lo == self.hi and not math.isinf(self.lo)

    @property
    def bounded(self) -> bool:
        return not (math.isinf(self.lo) or math.isinf(self.hi))


def point(value: float) -> Span:
    return Span(value, value)


ZERO = point(0)
UNKNOWN = Span(-INF, INF)


class Path(NamedTuple):
    """Vectors of one axis run in order from a start: their total and the lowest and
    highest partial sums (0 included: where the path starts)."""

    total: Span = ZERO
    low: float = 0
    high: float = 0

    def then(self, step: Span) -> Path:
        lo, hi = self.total.lo + step.lo, self.total.hi + step.hi
        return _new(Path, (_new(Span, (lo, hi)), min(self.low, lo), max(self.high, hi)))

    @property
    def swing(self) -> Span:
        return Span(self.low, self.high)


EMPTY = Path()


class Outcome(enum.Enum):
    ACCEPTED = "accepted"      # the unit answered the command with code 0
    REFUSED = "refused"        # a well-formed error code: nothing of it was executed
    UNCLEAR = "unclear"        # no answer, or bytes that are not one: maybe either


class Read(enum.Enum):
    """What a position read told the bookkeeping (:meth:`Envelope.observe`)."""

    MOVING = "moving"          # taken while something may move: it tells nothing
    AGREES = "agrees"          # where the frames put the axes: the trail starts again
    UNHELD = "unheld"          # a counter set with N<axis> that does not hold its value
    RESTARTED = "restarted"    # the power-on counters (spec 9) where the frames say other
    CONTRADICTS = "contradicts"   # other counters than the frames allow: restarted, or moved


class Envelope:
    """One unit's axes for the whole run, in counter units from where the run began."""

    #: a copy a frame is judged on (:meth:`would_reach`): where the axes may have been
    #: is not kept on it
    trial = False

    def __init__(self, axes: int, limit: float, factors: Sequence[int] = (1,),
                 reset_factor: int = 1) -> None:
        self.axes = axes
        self.limit = limit                       # counter units either side of the start
        self.start = [ZERO] * axes               # where the queue begins (physical)
        self.queue = [EMPTY] * axes              # accepted, not shown ended
        #: where the run of K's save may take each axis (None: no save held)
        self.saved: list[Span] | None = None
        self.save_moves = False                  # the save holds a vector
        #: how far a save `R` gave back moves the axes should it run again: that `R`
        #: empties the save is a decision (spec 10.5 [D]), and a unit that keeps it runs
        #: it once more after another `R` and `G`, from wherever the axes then stand
        #: (None: no save given back, or a `K` or restart since)
        self.rerun: list[Span] | None = None
        self.settled = True                      # nothing can be moving now
        self.offset = [UNKNOWN] * axes           # physical = counter + offset
        self.factor = Span(min(factors), max(factors))   # counter units per commanded step
        self.reset_factor = reset_factor
        self.seen = [ZERO] * axes                # every place an axis may have been
        self.trail = [ZERO] * axes               # ... since a read at rest last agreed
        self.set_counters = False                # N/N<axis> taken since the last read at rest
        self.unheld: list[int] = []              # axes whose set counter read back otherwise
        #: an `SW6` taken while vectors were held: ST6's RUN may be what it wrote
        self.st6_written = False

    # -- what the unit may do ---------------------------------------------------------------
    def reach(self) -> list[Span]:
        """Per axis, every position the axis may be at now or reach with what it accepted."""
        return [_new(Span, (s.lo + q.low, s.hi + q.high))
                for s, q in zip(self.start, self.queue, strict=True)]

    def would_reach(self, event: Callable[[Envelope], None]) -> list[Span]:
        """The reach after ``event`` (applied to a copy): how to judge a frame before it
        is sent."""
        trial = object.__new__(type(self))     # copy.copy's shallow copy, at less cost
        trial.__dict__.update(self.__dict__)
        trial.start, trial.queue, trial.offset = list(self.start), list(self.queue), \
            list(self.offset)
        trial.trial = True
        event(trial)
        return trial.reach()

    def outside(self, spans: list[Span]) -> int | None:
        """The first axis whose span leaves the envelope, or None."""
        for i, s in enumerate(spans):
            if s.lo < -self.limit or s.hi > self.limit:
                return i
        return None

    def position(self) -> list[float | None]:
        """Where each axis rests, when that is known exactly (else None)."""
        known = self.settled and all(q == EMPTY for q in self.queue)
        return [s.lo if known and s.exact else None for s in self.start]

    # -- events -------------------------------------------------------------------------------
    def vector(self, steps: Sequence[Span], outcome: Outcome, *, stand_alone: bool) -> None:
        """`L` (``stand_alone``: accepted only when nothing is queued or running) or `C`
        with ``steps`` in commanded steps; also a packet member that was committed."""
        if outcome is Outcome.REFUSED:
            return
        if stand_alone and outcome is Outcome.ACCEPTED:
            self.ended()
        moves = [s.times(self.factor) for s in steps]
        if all(m == ZERO for m in moves):
            return              # a zero-length vector completes as it becomes current
        if outcome is Outcome.UNCLEAR:
            # maybe never taken: once the unit shows all ended, the axis is where the
            # vector leads or where it began, and only a read at rest tells which
            moves = [m.hull(ZERO) for m in moves]
        self.queue = [q.then(m) for q, m in zip(self.queue, moves, strict=True)]
        self.settled = False
        self._see()

    def ended(self) -> None:
        """The unit showed that everything it accepted has ended (RUN = 0, or an `L` or
        `N` it took, which it takes only then)."""
        self._carry([q.total for q in self.queue])
        self.start = [s + q.total for s, q in zip(self.start, self.queue, strict=True)]
        self.queue = [EMPTY] * self.axes
        self.settled = True
        self.st6_written = False

    def _carry(self, moves: Sequence[Span]) -> None:
        """The axes moved by ``moves`` while a save is held: its run, which starts from
        wherever they stand at `R`, moves with them."""
        if self.saved is not None:
            self.saved = [s + m for s, m in zip(self.saved, moves, strict=True)]

    def _cut(self) -> None:
        """The queue stops counting (emptied, or run into the start): it may have run
        any part of its way."""
        self._carry([q.swing for q in self.queue])
        self.start = self.reach()
        self.queue = [EMPTY] * self.axes
        self.st6_written = False

    def discard(self, outcome: Outcome, *, keep: bool = False, restart: bool = False) -> None:
        """`D` (the queue emptied where the axes stand), `K` (``keep``: the queue saved
        whole) or `J` (``restart``: counters zeroed, micro-step mode reset)."""
        if outcome is Outcome.REFUSED:
            return
        sure = outcome is Outcome.ACCEPTED
        if keep:
            # the save's run goes wherever the queue could still go from here
            kept, moves = self.reach(), any(q != EMPTY for q in self.queue)
            self._cut()
            if sure:
                self.rerun = None
            if sure or self.saved is None:
                self.saved, self.save_moves = kept, moves
            else:
                self.saved = [a.hull(b) for a, b in zip(self.saved, kept, strict=True)]
                self.save_moves = self.save_moves or moves
        else:
            self._cut()
        if restart:
            if sure:
                self.saved, self.rerun = None, None
            self.offset = list(self.start) if sure else [
                o.hull(s) for o, s in zip(self.offset, self.start, strict=True)]
            reset = point(self.reset_factor)
            self.factor = reset if sure else self.factor.hull(reset)
        self.settled = sure

    def restore(self, outcome: Outcome) -> None:
        """`R`: the saved queue replaces what is held and runs after `G` from where the
        axes stand: they may then be anywhere its run goes, and rest there once the unit
        shows it ended (a read at rest tells where). A save given back may run again
        (:attr:`rerun`) from wherever the axes stand at a later `R`."""
        if outcome is Outcome.REFUSED:
            return
        self._cut()
        before = self.start
        if self.rerun is not None:
            self.start = [a.hull(a + d) for a, d in zip(self.start, self.rerun, strict=True)]
        moves = self.saved is not None and self.save_moves
        if moves:
            self.start = [a.hull(b) for a, b in zip(self.start, self.saved, strict=True)]
            # run again, it goes as far from wherever it starts (its own run's reach)
            ran = [s - b for s, b in zip(self.saved, before, strict=True)]
            self.rerun = ran if self.rerun is None else [
                a.hull(b) for a, b in zip(self.rerun, ran, strict=True)]
        if outcome is Outcome.ACCEPTED:
            self.saved, self.save_moves = None, False
        moves = moves or self.rerun is not None
        self.settled = outcome is Outcome.ACCEPTED and not moves
        self._see()

    def counters(self, values: dict[int, int | None], outcome: Outcome, *,
                 every_axis: bool = True) -> None:
        """`N` (``every_axis``: every axis to 0) or `N<axis> n`: the counters move, the
        axes do not. A unit takes `N` only when nothing runs (spec 5 [M]: 7 whenever
        RUN = 1); `N<axis>` too by our decision only, so a unit may take it with a halted
        remainder held, or while the axes move (M114 sets no bar on it): the counter is
        then set wherever on the queue's way the axis stands. A value of None: the
        counter's new value is not known."""
        if outcome is Outcome.REFUSED:
            return
        if outcome is Outcome.ACCEPTED and every_axis:
            self.ended()
        for axis, value in values.items():
            here = self.start[axis] + (self.queue[axis].total if every_axis
                                       else self.queue[axis].swing)
            new = UNKNOWN if value is None else here - point(value)
            self.offset[axis] = new if outcome is Outcome.ACCEPTED else self.offset[axis].hull(new)
        self.set_counters = self.set_counters or bool(values)

    def reference(self, axis: int, travel: Span, outcome: Outcome, *, zeroed: bool) -> None:
        """`W`: the axis moves anywhere within ``travel`` (to the switch and back); the
        counter is 0 where the switch releases (``zeroed``) or moved with the axis."""
        if outcome is Outcome.REFUSED:
            return
        if outcome is Outcome.ACCEPTED:
            self.ended()
        else:
            self._cut()
        self._carry([travel if a == axis else ZERO for a in range(self.axes)])
        self.start[axis] = self.start[axis] + travel
        if zeroed or outcome is Outcome.UNCLEAR:
            self.offset[axis] = self.start[axis] if outcome is Outcome.ACCEPTED else \
                self.offset[axis].hull(self.start[axis])
        self.settled = outcome is Outcome.ACCEPTED
        self._see()

    def mode(self, factor: int, outcome: Outcome) -> None:
        """GVE54 `M`: later vectors are in steps of ``factor`` counter units (spec 10.7)."""
        if outcome is Outcome.ACCEPTED:
            self.factor = point(factor)
        elif outcome is Outcome.UNCLEAR:
            self.factor = self.factor.hull(point(factor))

    def write_st6(self, outcome: Outcome) -> None:
        """`SW6`: it may start or stop motion the bookkeeping already counts, and a unit
        may store the RUN bit it was given (the manuals: it writes ST6), so RUN = 0 read
        after it no longer shows that the queue has ended."""
        if outcome is not Outcome.REFUSED and any(q != EMPTY for q in self.queue):
            self.st6_written = True
        self.unsettle()

    def unsettle(self) -> None:
        """Something may have started motion that the bookkeeping already counts (`G`,
        `SW6`)."""
        if any(q != EMPTY for q in self.queue):
            self.settled = False

    # -- what the unit says ------------------------------------------------------------------
    def origin(self, counters: dict[int, int]) -> None:
        """The first position read: the counters where the run begins."""
        for axis, value in counters.items():
            self.offset[axis] = point(-value)
        self.trail = list(self.start)

    def expected(self, axes: Sequence[int]) -> list[Span]:
        """What the counters of ``axes`` should read now, by the frames."""
        return [self.start[a] + self.queue[a].total - self.offset[a] for a in axes]

    def observe(self, counters: dict[int, int], *, silence: bool = False) -> Read:
        """A position read (`PF`, `P`). Only while nothing can move does it tell where an
        axis rests. Counters the frames cannot explain are not believed over them: all 0
        where the frames say otherwise are the power-on counters of a unit that
        restarted by itself (spec 9); others the counters of a restart the unit has moved
        on from, or of axes moved by other means (a hand-wheel). Either way the axes may
        be anywhere their trail has been, the counters counting from there
        (:meth:`lose_track`). So may they after ``silence`` (frames went unanswered since
        the last read that agreed, as they do while a unit restarts) when all 0 agrees
        only because the frames ended the axes where the counters began."""
        if not self.settled or any(q != EMPTY for q in self.queue):
            return Read.MOVING
        known = {a: v for a, v in counters.items() if self.offset[a].bounded}
        met = {a: self.start[a].meet(point(v) + self.offset[a]) for a, v in known.items()}
        zeros = bool(counters) and all(v == 0 for v in counters.values())
        wrong = [a for a, m in met.items() if m is None]
        unheld = [a for a in wrong if self.set_counters
                  and self.outside([point(known[a]) + self.offset[a]]) is not None]
        if wrong and len(unheld) == len(wrong):
            # a counter set since the last read at rest reads the axis beyond the
            # envelope the guard never let it leave: taken for a counter that does not
            # hold the value set (a narrow one wraps), not for axes moved millions of
            # steps; the frames' bookkeeping stays and the counter is anchored to it again
            for a in unheld:
                self.offset[a] = self.start[a] - point(known[a])
            self.unheld += unheld
            wrong = []
        elif wrong or (zeros and silence and not all(t.exact for t in self.trail)):
            self.lose_track(counters, restarted=zeros)
            return Read.RESTARTED if zeros else Read.CONTRADICTS
        for a, m in met.items():
            if m is not None:
                self.start[a] = m
        self.set_counters = False
        self.trail = list(self.start)
        self._see()
        return Read.UNHELD if unheld else Read.AGREES

    def lose_track(self, counters: dict[int, int], *, restarted: bool) -> None:
        """The counters read ``counters`` at rest and the frames cannot explain them. A
        unit that restarted stopped somewhere on its trail and counts from 0 there
        (spec 9), then from every frame since: the axis is on its trail plus what it
        reads. Unless ``restarted`` (every counter 0), it may also be where the counter
        says, as the frames counted it (moved by other means). Nothing is queued or saved
        any more; an axis not read stays anywhere on its trail."""
        for a in range(self.axes):
            trail = self.trail[a]
            read = counters.get(a)
            if read is None:
                self.start[a], self.offset[a] = trail, UNKNOWN
                continue
            here = trail + point(read)
            if restarted or not self.offset[a].bounded:
                self.start[a], self.offset[a] = here, trail
            else:
                self.start[a] = here.hull(point(read) + self.offset[a])
                self.offset[a] = self.offset[a].hull(trail)
        if restarted:
            self.factor = point(self.reset_factor)
        self.queue, self.saved, self.settled = [EMPTY] * self.axes, None, True
        if restarted:
            self.rerun = None
        self.set_counters = False
        self.trail = list(self.start)
        self._see()

    def locate(self, physical: dict[int, int], counters: dict[int, int]) -> None:
        """The axes are at rest at ``physical`` (counter units from where the run began,
        as a test rig's eyes saw them) while the counters read ``counters``: where they
        are is known again."""
        self.queue, self.settled = [EMPTY] * self.axes, True
        for a, value in physical.items():
            self.start[a] = point(value)
            if a in counters:
                self.offset[a] = point(value - counters[a])
        self.trail = list(self.start)
        self._see()

    def anchor(self, counters: dict[int, int]) -> None:
        """Counters read while the axes are known not to have moved since the bookkeeping
        last knew them (at rest, right after a set of the counters): each is anchored to
        where the bookkeeping has its axis, so a counter that did not take the set is not
        taken for motion (only while nothing can move: else it tells nothing)."""
        if not self.settled or any(q != EMPTY for q in self.queue):
            return
        for axis, value in counters.items():
            self.offset[axis] = self.start[axis] - point(value)
        self.set_counters = False
        self.trail = list(self.start)

    def _see(self) -> None:
        if self.trial:
            return              # a trial's places seen are not kept: only its reach is read
        reach = self.reach()
        self.seen = [a.hull(b) for a, b in zip(self.seen, reach, strict=True)]
        self.trail = [a.hull(b) for a, b in zip(self.trail, reach, strict=True)]
