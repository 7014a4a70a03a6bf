"""A motion scenario on a link, measured: frames are sent with the window in which the
unit processed them, the motion they cause is booked in the suite's model, positions are
read with ``PF``, and at the end every reading is judged against the model at its
instant, within the tolerance of :mod:`conformance.motion.tolerance` (printed with each
check where it has a width; exact, and not printed, against the reference emulator or a
target run with --strict in virtual time), and the whole is
recorded as a trace for the reports, with what failed marked on it.

The probe interprets the frames it sends as the unit must (spec 10): modal parameters
(``V A B $ T VK VN VL M``) are captured by the vectors accepted after them, ``XM XA XU
XD`` act on the queue at once, ``H`` and ``G`` halt and resume. On the GVE54 vectors, ``V``,
``B``, ``A``, ``$`` and the maximum rate are in commanded steps and scaled to the
1/16-step counters by the micro-step factor (docs/decisions.md).
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass, field, replace

from conformance.case.context import CaseContext, CouldNotTest
from conformance.known_state.limits import known_axis_limits
from conformance.link.account import Spent
from conformance.link.framing import Response, frame
from conformance.link.line_band import EXACT, LineBand, acted_within, line_band
from conformance.link.line_time import MARGIN
from conformance.link.link import Link
from conformance.motion.model import DWELL_TICK, MotionModel
from conformance.motion.plan import Params, dominant
from conformance.motion.tolerance import (
    TICK_NS,
    Tolerance,
    Window,
    answer_window,
    late_window,
    processing_window,
    step_period,
    tolerance,
    widened,
)
from conformance.protocol.catalogue import catalogue, classes
from conformance.protocol.parse import parse
from gve_fixtures.profile import Profile
from gve_fixtures.protocol import SECOND, ErrorCode
from gve_fixtures.rules import load_rules

#: the rule a reading off the model by no more than another placement of its steps is
#: graded by (spec 10.2 [D])
PLACEMENT_RULE = "10.2.motion.step-placement"
#: the rule a reading off the model is graded by where the whole scenario is the model's
#: whose VK vectors take A along the path (spec 10.2 [D])
PATH_ACCEL_RULE = "10.2.motion.path-accel"
#: dense model points per trace
TRACE_POINTS = 60
#: let the unit rest longer than any T (24 ms) before a scenario starts
SETTLE = 0.03
#: a scenario's moves take well under this
UNTIL_SECONDS = 5.0
_VECTORS = classes(vector=True)
_MODAL = classes(modal=True)
_SWITCHES = classes(switch=True)
_EXCHANGES = classes(exchanges=True)


def _stated_instead(body: str, r: Response | None, profile: Profile) -> str | None:
    """The frame setting ``body``'s modal parameter to the reset value, when ``body`` was
    refused as out of a range no manual states (None: it was not, or that is it)."""
    head, _ = _split(body)
    if r is None or r.code is None or r.code & 7 != ErrorCode.RANGE or head not in _MODAL:
        return None
    rules = load_rules()
    if any(rules[rule].tag != "D" for rule in catalogue()[head].rules if rule in rules):
        return None
    value = {"$": profile.reset.dollar}.get(head, getattr(profile.reset, head, None))
    stated = None if value is None else f"{head}{value}"
    return stated if stated != body else None


@dataclass
class Event:
    window: Window
    kind: str                 # push, override, halt, go
    args: dict = field(default_factory=dict)
    answer: Window | None = None    # H: when its answer left the unit


@dataclass
class Reading:
    window: Window
    positions: list[int]
    label: str


class Probe:
    def __init__(self, ctx: CaseContext, name: str, rule: str) -> None:
        self.ctx, self.name, self.rule = ctx, name, rule
        self.link = ctx.link
        #: exactness is ours only against the reference, or a target run --strict, in
        #: virtual time: elsewhere step placement and rounding are the target's own
        self.exact = self.link.virtual and ctx.target.strict
        #: the models with each event a step period either side (judge's, once needed)
        self._placements: list | None = None
        p = ctx.profile
        r = p.reset
        self.scale = 1 if p.microstep is None else p.microstep.factors[p.microstep.reset_mode]
        # the state a case starts from: a fresh emulated unit, or a real one put into the
        # known state (docs/suite.md), whose VL cannot always be set back to the reset's
        fresh = not ctx.target.real
        vl = r.VL if fresh or "VL" not in p.commands else known_axis_limits(p)
        self.modal = {"V": r.V, "A": r.A, "B": r.B, "$": r.dollar, "T": r.T, "VK": r.VK,
                      "VL": tuple(vl)}
        self.events: list[Event] = []
        self.readings: list[Reading] = []
        self.params: dict = {}
        self.round_trip = 0
        self.next_brake = False    # model the junctions at the next C's B (a [D] reading)
        self.start_delay = 0       # ns: a dwell before every start from rest (a reading)
        self.accel_along_path = False   # VK vectors take A along |d| (a reading)
        self.trips: list[int] = []          # ns: the round trips of frames answered at once
        self.link.wait(SETTLE, Spent.MANUAL)      # the longest dwell T the manual allows
        start = self.read("start")
        if start is None:
            raise CouldNotTest("PF did not answer with positions before the motion")
        self.origin = start

    # -- the link -----------------------------------------------------------------------
    def _timing(self, body: str, r: Response) -> tuple[Window, Window]:
        """When the unit took the frame, and when its answer left."""
        n = len(frame(body, self.link.address, self.link.checksums))
        # a serial: target may be a pseudo-terminal, whose bytes take no time: only the
        # round trip is sure (a line known to be paced could leave the bytes' time out)
        kw = {"virtual": self.link.virtual, "paced": False}
        answered = answer_window(r.sent_at, r.received_at, n, len(r.raw), self.link.baud, **kw)
        if body[:1] == "H":
            return late_window(r.sent_at, n, self.link.baud, self.round_trip, **kw), answered
        self.round_trip = max(self.round_trip, r.received_at - r.sent_at)
        self.trips.append(r.received_at - r.sent_at)
        return processing_window(r.sent_at, r.received_at, n, len(r.raw), self.link.baud,
                                 **kw), answered

    def send(self, body: str) -> Response:
        """Send a frame the scenario needs (the case cannot judge when it is refused) and
        book what it does. A modal value refused as out of a range the manuals do not
        state (its range rule [D]: another reading may take fewer values) is sent again
        at the unit's reset value, which its manual states, and the scenario is measured
        under that."""
        r = self.link.send(body)
        stated = _stated_instead(body, r, self.ctx.profile)
        if stated is not None:
            self.ctx.note(f"{body} answered {r.text} (a range the manuals do not state): "
                          f"measured with {stated}, the reset value")
            body, r = stated, self.link.send(stated)
        r = _when_done(self.link, body, r, self.ctx.profile)
        self.ctx.require(r is not None and r.ok, f"{body} answered "
                         f"{'nothing' if r is None else r.text}, expected 0")
        self._book(body, *self._timing(body, r))
        return r

    def read(self, label: str = "") -> list[int] | None:
        """Read PF and keep the reading (None when the unit did not answer with positions;
        bytes that are not decimals fail the case through the response's accessor)."""
        r = self.link.send("PF")
        if r is None or not r.ok or len(r.values) < 3:
            return None
        values = r.decs()
        self.readings.append(Reading(self._timing("PF", r)[0], values, label))
        return values

    def sample(self, seconds: float, every: float, label: str = "") -> None:
        """Read PF every ``every`` s for ``seconds``."""
        end = self.link.now + round(seconds * SECOND)
        while self.link.now < end:
            self.link.wait(every, Spent.MOTION)
            self.read(label)

    def until(self, target: list[int], max_seconds: float, every: float) -> None:
        """Read PF every ``every`` s until the axes stand at ``target`` (counter units)."""
        end = self.link.now + round(max_seconds * SECOND)
        while self.link.now < end:
            got = self.read()
            if got is not None and got[:len(target)] == target:
                return
            self.link.wait(every, Spent.MOTION)
        raise CouldNotTest(f"the axes did not reach {target} within {max_seconds} s")

    def script(self, steps: list, every: float = 0.05) -> bool:
        """Run a scenario and judge it: a string is a frame to send, a number the seconds
        to sample PF for (every ``every`` s; a pair: seconds and how often), a list the
        position (in commanded steps) to poll PF until (every 2 ms)."""
        self.run(steps, every)
        return self.judge()

    def run(self, steps: list, every: float = 0.05) -> None:
        """Run a scenario (as :meth:`script`) without judging it yet."""
        for step in steps:
            if isinstance(step, str):
                self.send(step)
            elif isinstance(step, tuple):
                self.sample(*step)
            elif isinstance(step, list):
                self.until([o + x * self.scale for o, x in zip(self.origin, step, strict=False)],
                           UNTIL_SECONDS, 0.002)
            else:
                self.sample(step, every)

    # -- the frames' meaning (spec 10) --------------------------------------------------
    def _book(self, body: str, w: Window, answered: Window) -> None:
        head, rest = _split(body)
        if head in _VECTORS:
            d = tuple(int(x) * self.scale for x in rest.split(","))
            self.events.append(Event(w, "push", {"d": d, "kind": head,
                                                 "p": self._captured()}))
        elif head in _SWITCHES:
            self.modal["VK"] = head == "VK"
            self.params["VK" if head == "VK" else "VN"] = True
        elif head == "VL":
            values = [int(x) for x in rest.split(",")]
            self.modal["VL"] = tuple(values) + self.modal["VL"][len(values):]
            self.params["VL"] = values
        elif head == "M":
            self.scale = self.ctx.profile.microstep.factors[rest]
            self.params["M"] = rest
        elif head == "XM":
            self.events.append(Event(w, "override", {"name": "XM", "value": int(rest)}))
            self.params["XM"] = int(rest)
        elif head in _MODAL:                 # one value each: V, A, B, $, T
            self.modal[head] = int(rest)
            self.params[head] = int(rest)
        elif head in _EXCHANGES:
            p = self._captured()             # XA: the modal V (GVE54: and A) as it is now
            self.events.append(Event(w, "override", {
                "name": head, "modal_v": p.V, "modal_a": p.A,
                "scales_accel": self.ctx.profile.microstep is not None}))
            self.params[head] = True
        elif head == "H":
            self.events.append(Event(w, "halt", answer=answered))
        elif head == "G":
            self.events.append(Event(w, "go"))

    def _captured(self) -> Params:
        m, s = self.modal, self.scale
        max_rate = self.ctx.profile.max_rate
        vl = tuple(min(v, max_rate) for v in m["VL"])
        return Params(V=m["V"] * s, A=m["A"] * 1000 * s, B=m["B"] * s, dollar=m["$"] * s,
                      T=m["T"] * 1_000_000, max_rate=max_rate * s, VK=m["VK"], VL=vl)

    # -- judging --------------------------------------------------------------------------
    def model(self, shift: dict[int, int] | None = None) -> tuple[MotionModel, list[int]]:
        """The model fed with every event at its instant: the middle of its window, or
        for the events in ``shift`` (index -> instant) that instant; and the instant it
        comes to rest after each H."""
        model = MotionModel(self.origin, next_brake=self.next_brake,
                            start_delay=self.start_delay)
        rests = []
        for i, e in enumerate(self.events):
            t = (shift or {}).get(i, (e.window.lo + e.window.hi) // 2)
            if e.kind == "push":
                p = e.args["p"]
                model.push(t, e.args["d"], e.args["kind"],
                           _along_path(e.args["d"], p) if self.accel_along_path else p)
            elif e.kind == "override":
                model.override(t, **e.args)
            elif e.kind == "halt":
                rests.append(model.halt(t))
            elif e.kind == "go":
                model.go(t)
        last = max([r.window.hi for r in self.readings] + [e.window.hi for e in self.events])
        model.advance(last)
        return model, rests

    def _variants(self) -> list[tuple[MotionModel, list[int]]]:
        """The model with each event moved to either end of its window (the others in the
        middle): how much not knowing when the unit took a frame can change the motion.
        On the emulator's virtual clock every window is an instant: no variant."""
        out = []
        for i, e in enumerate(self.events):
            if e.window.lo != e.window.hi:
                out += [self.model({i: e.window.lo}), self.model({i: e.window.hi})]
        return out

    def _read_dwell(self) -> None:
        """Where exactness is not ours, a unit may dwell before every start from rest
        (its own T, on its own tick), not only T after its last rest (10.2.motion.dwell
        gives the earliest start alone): a scenario the model misses is judged by the
        model whose every start from rest waits one delay, of whole milliseconds (the
        unit T is given in) up to the longest T of the scenario and a tick, when the
        whole of it fits there — one delay for the whole scenario, so a dwell where the
        manual says there is none still shows."""
        if self.exact or self.fits():
            return
        longest = max((e.args["p"].T for e in self.events if e.kind == "push"), default=0)
        for delay in range(DWELL_TICK, longest + 2 * DWELL_TICK, DWELL_TICK):
            self.start_delay = delay
            if self.fits():
                return
        self.start_delay = 0

    def _reads_path_accel(self) -> bool:
        """Where exactness is not ours and the model misses a scenario with VK vectors:
        whether the whole scenario is the model's whose VK vectors take A along the path
        (the dominant axis at A·n/|d|), with a dwell before each start as :meth:`_read_dwell`
        finds one. M84 12.5.4 measures the speed along |d| and does not say along which
        length A runs: each reading the model misses is then graded by that [D] rule."""
        if self.exact or not any(e.kind == "push" and e.args["p"].VK for e in self.events) \
                or self.fits():
            return False
        delay, self.accel_along_path = self.start_delay, True
        try:
            self._read_dwell()
            return self.fits()
        finally:
            self.accel_along_path, self.start_delay = False, delay

    def _banded(self, model: MotionModel, variants: list, line: LineBand, t0: int,
                spread: int, exact: bool) -> Iterator[tuple[Reading, Tolerance, list]]:
        """Each reading taken after the first event, with its tolerance and its band."""
        for reading in self.readings:
            w = reading.window
            if w.hi - line.ns < t0:
                continue
            tol = tolerance(Window(0, w.hi - w.lo + spread), exact=exact, line=line)
            yield reading, tol, _band(model, variants, w, tol.steps)

    def fits(self) -> bool:
        """Whether every reading after the first event lies within the model's band, the
        line's band included (as :meth:`judge` would find), recording nothing."""
        line = self.line()
        events, readings = self.events, self.readings
        try:
            self._answered_late()
            self._widen(line)
            (model, _), variants = self.model(), self._variants()
            t0 = (self.events[0].window.lo if self.events else self.readings[0].window.lo
                  ) + line.ns
            spread = sum(e.window.hi - e.window.lo for e in self.events)
            for reading, _, band in self._banded(model, variants, line, t0, spread,
                                                 self.exact):
                got = reading.positions[:len(band)]
                if not all(b0 <= g <= b1 for g, (b0, b1) in zip(got, band, strict=True)):
                    return False
            return True
        finally:
            self.events, self.readings = events, readings

    def line(self) -> LineBand:
        """The line's band: zero in virtual time; in real time from the round trip the
        session measured and those the scenario saw."""
        if self.link.virtual:
            return EXACT
        return line_band(self.link.round_trip, [t / 1e6 for t in self.trips])

    def _answered_late(self) -> None:
        """Real time: each H's window reaches as late as its answer shows it may have been
        taken (conformance/link/line_band.py, :func:`acted_within`): its answer left no
        sooner than the model's braking after it, and the line may have carried that
        frame alone later than any round trip before it shows."""
        if self.link.virtual:
            return
        for i, e in enumerate(self.events):
            if e.kind != "halt" or e.answer is None:
                continue
            lo, latency = e.window.lo, e.window.hi - e.window.lo
            took = self._braking(i, e.window.hi)
            hi = lo + acted_within(lo, e.answer.hi, took, latency)
            if hi > e.window.hi:
                # taken later, it may brake from another rate: the shorter braking of the
                # two (the later instant) bounds it
                took = min(took, self._braking(i, hi))
                hi = lo + acted_within(lo, e.answer.hi, took, latency)
            late = replace(e, window=Window(lo, max(e.window.hi, hi)))
            self.events = [*self.events[:i], late, *self.events[i + 1:]]

    def _braking(self, i: int, t: int) -> int:
        """How long the model's event ``i`` (an H) taken at ``t`` brakes until at rest."""
        nth = sum(e.kind == "halt" for e in self.events[:i])
        return self.model({i: t})[1][nth] - t

    def _widen(self, line: LineBand) -> None:
        """Every event's and reading's window widened by the line's band: the unit may
        have acted (or read its counters) that much either side of what the host saw."""
        if line.exact:
            return
        self.events = [replace(e, window=widened(e.window, line),
                               answer=e.answer and widened(e.answer, line))
                       for e in self.events]
        self.readings = [replace(r, window=widened(r.window, line)) for r in self.readings]

    def judge(self) -> bool:
        """Judge every reading taken after the first event, and the instant each H
        answered, with the line's band; record the trace, with the faults marked on it."""
        self._read_dwell()
        along_path = self._reads_path_accel()
        line = self.line()
        self._answered_late()
        self._widen(line)
        (model, rests), variants = self.model(), self._variants()
        exact = self.exact
        # instants are printed from the first event as the host saw it, the band left out
        t0 = (self.events[0].window.lo if self.events else self.readings[0].window.lo) + line.ns
        spread = sum(e.window.hi - e.window.lo for e in self.events)
        ok_all = True
        faults: list[dict] = []
        widest = tolerance(Window(0, spread), exact=exact, line=line)
        halts = [e for e in self.events if e.kind == "halt"]
        # another placement of the steps may come to rest up to a step period either side
        period = 0 if exact else step_period(self._slowest_ramp())
        self._placements = None
        for n, (e, rest) in enumerate(zip(halts, rests, strict=True)):
            # what each event's window can change, added up (as for positions)
            lo = rest + sum(min(0, v[1][n] - rest) for v in variants) - period
            hi = rest + sum(max(0, v[1][n] - rest) for v in variants) + period
            a = e.answer
            tol = tolerance(Window(0, a.hi - a.lo + hi - lo), exact=exact, line=line)
            ok = lo <= a.hi and a.lo <= hi
            rule = PATH_ACCEL_RULE if not ok and along_path else self.rule
            ok = self.ctx.expect(
                ok, f"{self.name}: H answered when the motion came to rest{_within(tol)}",
                observed=f"answer at {(a.lo + line.ns - t0) / 1e6:.3f} ms",
                expected=f"at rest at {(rest - t0) / 1e6:.3f} ms", rule=rule,
                machinery=rule != self.rule)
            ok_all &= ok
            if not ok:
                faults.append({"kind": "instant", "what": "H answered",
                               "observed": (a.lo + line.ns - t0) / SECOND,
                               "expected": [(lo - t0) / SECOND, (hi - t0) / SECOND],
                               "expected_what": "at rest"})
        for reading, tol, band in self._banded(model, variants, line, t0, spread, exact):
            w = reading.window
            tol = replace(tol, band=max(math.ceil((b1 - b0) / 2) for b0, b1 in band))
            widest = max(widest, tol, key=lambda x: x.seconds)
            got = reading.positions[:len(band)]
            ok = all(b0 <= g <= b1 for g, (b0, b1) in zip(got, band, strict=True))
            expected = [b0 + tol.steps if b0 + tol.steps == b1 - tol.steps else f"{b0}..{b1}"
                        for b0, b1 in band]
            # the reading that explains the whole scenario names the rule of what it misses
            rule = self.rule if ok else PATH_ACCEL_RULE if along_path else PLACEMENT_RULE \
                if self._placed(model, variants, w, tol, got, period) else self.rule
            ok_all &= self.ctx.expect(
                ok, f"{self.name}: PF at {(w.lo + line.ns - t0) / 1e6:.3f} ms"
                f"{' ' + reading.label if reading.label else ''}{_within(tol)}",
                observed=got, expected=expected, rule=rule, machinery=rule != self.rule)
            if not ok:
                t = ((w.lo + w.hi) / 2 - t0) / SECOND
                faults += [{"kind": "position", "t": t, "axis": i, "observed": g,
                            "expected": [b0, b1]}
                           for i, (g, (b0, b1)) in enumerate(zip(got, band, strict=True))
                           if not b0 <= g <= b1]
        self._trace(model, t0, widest, faults)
        return ok_all

    def _placed(self, model: MotionModel, variants: list, w: Window, tol: Tolerance,
                got: list[int], period: int) -> bool:
        """Whether ``got``, outside the band, is the model's a step period either side:
        another placement of the same ramps' steps (where a unit's arithmetic puts a
        ramp's first step, or takes an event at its next step, the manuals do not say),
        graded by the placement's [D] rule rather than the case's."""
        if not period:
            return False
        if self._placements is None:
            # each event the unit may take up to a step period, and a tick of its own
            # (tolerance.py: the manuals fix no clock finer than the millisecond), either
            # side of its window
            shift = period + TICK_NS
            self._placements = variants + [
                self.model({i: t}) for i, e in enumerate(self.events)
                for t in (e.window.lo - shift, e.window.hi + shift)]
        band = _band(model, self._placements, Window(w.lo - period, w.hi + period),
                     tol.steps)
        return all(b0 <= g <= b1 for g, (b0, b1) in zip(got, band, strict=True))

    def _slowest_ramp(self) -> int:
        """The smallest acceleration a vector of the scenario captured (steps/s²)."""
        return min((e.args["p"].A for e in self.events if e.kind == "push"), default=0)

    def _trace(self, model: MotionModel, t0: int, tol, faults: list[dict]) -> None:
        end = max(r.window.hi for r in self.readings)
        end = max(end, model.rest)
        step = max(1, (end - t0) // TRACE_POINTS)
        instants = sorted({*range(t0, end + 1, step), end,
                           *((r.window.lo + r.window.hi) // 2 for r in self.readings
                             if r.window.hi >= t0)})
        self.ctx.trace(self.name,
                       samples=[((r.window.lo + r.window.hi) / 2 / SECOND - t0 / SECOND,
                                 r.positions) for r in self.readings if r.window.hi >= t0],
                       model=[((t - t0) / SECOND, model.position(t)) for t in instants],
                       tolerance=tol.as_dict(), params=dict(self.params), faults=faults)


def _within(tol: Tolerance) -> str:
    """The band a check used, for its text; none where the check is exact."""
    return "" if tol.exact else f" ({tol})"


def _when_done(link: Link, body: str, r: Response | None, profile: Profile
               ) -> Response | None:
    """An `L` answered 1 ("Dokud není přijat, karta hlásí chybu 1, a tudíž fronta před ním
    není hotová"): a unit may count the T dwell after the vector before it as part of the
    queue. Sent again every tick until it is answered otherwise, for at most the longest
    T and the line's margin; the model books it at the answer that took it. The last
    answer."""
    def busy(x: Response | None) -> bool:
        return x is not None and x.code is not None and x.code & 7 == ErrorCode.QUEUE_FULL
    if _split(body)[0] != "L" or not busy(r):
        return r
    limit = profile.range("T").hi / 1000 + 2 * MARGIN
    return link.poll(body, lambda x: not busy(x), limit, TICK_NS / SECOND) or r


def _along_path(d: tuple[int, ...], p: Params) -> Params:
    """``p`` of a vector ``d`` with A taken along the path |d| (the A axis left out, as
    for V under VK): the dominant axis accelerates at A·n/|d|. A VN vector keeps it."""
    path2 = sum(x * x for x in d[:3])
    if not p.VK or not path2:
        return p
    return replace(p, A=max(1, math.isqrt((p.A * dominant(d)) ** 2 // path2)))


def _split(body: str) -> tuple[str, str]:
    read = parse(body, strict=True)
    return (read.name, read.params) if read.name else (body[:1], body[1:])


def _band(model: MotionModel, variants: list[tuple[MotionModel, list[int]]], w: Window,
          steps: int) -> list[tuple[int, int]]:
    """Per axis, the least and greatest position the model gives over the reading's
    window, widened by what each event's own window can change (the variants, added up)
    and by ``steps``."""
    points = [model.position(t) for t in (w.lo, w.hi, *model.boundaries(w.lo, w.hi))]
    mid = model.position((w.lo + w.hi) // 2)
    out = []
    for i in range(len(points[0])):
        low = min(p[i] for p in points) - steps
        high = max(p[i] for p in points) + steps
        for v, _ in variants:
            here = v.position((w.lo + w.hi) // 2)[i] - mid[i]
            low, high = low + min(0, here), high + max(0, here)
        out.append((low, high))
    return out
