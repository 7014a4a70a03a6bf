"""A motion scenario on a link, measured: frames are sent with the window in which the
unit processed them, the motion they cause is booked in the suite's model, positions are
read with ``PF``, and at the end every reading is judged against the model at its
instant, within the tolerance of :mod:`conformance.motion.tolerance` (printed with each
check), and the whole is recorded as a trace for the reports.

The probe interprets the frames it sends as the unit must (spec 10): modal parameters
(``V A B $ T VK VN VL M``) are captured by the vectors accepted after them, ``XM XA XU
XD`` act on the queue at once, ``H`` and ``G`` halt and resume. On the GVE54 vectors, ``V``
and ``B`` are in commanded steps and scaled to the 1/16-step counters by the micro-step
factor (docs/decisions.md).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from conformance.case import CaseContext, CouldNotTest
from conformance.link.framing import Response, frame
from conformance.motion.arith import SECOND
from conformance.motion.model import MotionModel
from conformance.motion.plan import Params
from conformance.motion.tolerance import (
    Window,
    answer_window,
    late_window,
    processing_window,
    tolerance,
)

#: dense model points per trace
TRACE_POINTS = 60
#: let the unit rest longer than any T (24 ms) before a scenario starts
SETTLE = 0.03
#: a scenario's moves take well under this
UNTIL_SECONDS = 5.0


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
        p = ctx.profile
        r = p.reset
        self.scale = 1 if p.microstep is None else p.microstep.factors[p.microstep.reset_mode]
        self.modal = {"V": r.V, "A": r.A, "B": r.B, "$": r.dollar, "T": r.T, "VK": r.VK,
                      "VL": tuple(r.VL)}
        self.events: list[Event] = []
        self.readings: list[Reading] = []
        self.params: dict = {}
        self.round_trip = 0
        self.link.wait(SETTLE)
        start = self.read("start")
        if start is None:
            raise CouldNotTest("PF did not answer with positions before the motion")
        self.origin = start

    # -- the link -----------------------------------------------------------------------
    def _timing(self, body: str, r: Response) -> tuple[Window, Window]:
        """When the unit took the frame, and when its answer left."""
        n = len(frame(body, self.link.address, self.link.checksums))
        kw = {"virtual": self.link.virtual, "paced": self.ctx.target.kind == "serial"}
        answered = answer_window(r.sent_at, r.received_at, n, len(r.raw), self.link.baud, **kw)
        if body[:1] == "H":
            return late_window(r.sent_at, n, self.link.baud, self.round_trip, **kw), answered
        self.round_trip = max(self.round_trip, r.received_at - r.sent_at)
        return processing_window(r.sent_at, r.received_at, n, len(r.raw), self.link.baud,
                                 **kw), answered

    def send(self, body: str) -> Response:
        """Send a frame the scenario needs (the case cannot judge when it is refused) and
        book what it does."""
        r = self.link.send(body)
        self.ctx.require(r is not None and r.code == 0, f"{body} answered "
                         f"{'nothing' if r is None else r.text}, expected 0")
        self._book(body, *self._timing(body, r))
        return r

    def read(self, label: str = "") -> list[int] | None:
        r = self.link.send("PF")
        if r is None or r.code != 0 or len(r.values) < 3:
            return None
        try:
            values = [int(v) for v in r.values]
        except ValueError:
            return None
        self.readings.append(Reading(self._timing("PF", r)[0], values, label))
        return values

    def sample(self, seconds: float, every: float, label: str = "") -> None:
        """Read PF every ``every`` s for ``seconds``."""
        end = self.link.now + round(seconds * SECOND)
        while self.link.now < end:
            self.link.wait(every)
            self.read(label)

    def wait(self, seconds: float) -> None:
        self.link.wait(seconds)

    def until(self, target: list[int], max_seconds: float, every: float) -> None:
        """Read PF every ``every`` s until the axes stand at ``target`` (counter units)."""
        end = self.link.now + round(max_seconds * SECOND)
        while self.link.now < end:
            got = self.read()
            if got is not None and got[:len(target)] == target:
                return
            self.link.wait(every)
        raise CouldNotTest(f"the axes did not reach {target} within {max_seconds} s")

    def script(self, steps: list, every: float = 0.05) -> bool:
        """Run a scenario and judge it: a string is a frame to send, a number the seconds
        to sample PF for (every ``every`` s), a list the position (in commanded steps) to
        poll PF until (every 2 ms)."""
        for step in steps:
            if isinstance(step, str):
                self.send(step)
            elif isinstance(step, list):
                self.until([o + x * self.scale for o, x in zip(self.origin, step, strict=False)],
                           UNTIL_SECONDS, 0.002)
            else:
                self.sample(step, every)
        return self.judge()

    # -- the frames' meaning (spec 10) --------------------------------------------------
    def _book(self, body: str, w: Window, answered: Window) -> None:
        head, rest = _split(body)
        if head in ("L", "C"):
            d = tuple(int(x) * self.scale for x in rest.split(","))
            self.events.append(Event(w, "push", {"d": d, "kind": head,
                                                 "p": self._captured()}))
        elif head in ("V", "A", "B", "$", "T"):
            self.modal[head] = int(rest)
            self.params[head] = int(rest)
        elif head in ("VK", "VN"):
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
        elif head in ("XA", "XU", "XD"):
            self.events.append(Event(w, "override", {"name": head}))
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
    def model(self) -> tuple[MotionModel, list[tuple[Event, int]]]:
        """The model fed with every event at its instant (the window's middle), and the
        rest instant it gives each H."""
        model = MotionModel(self.origin)
        halts = []
        for e in self.events:
            t = (e.window.lo + e.window.hi) // 2
            if e.kind == "push":
                model.push(t, e.args["d"], e.args["kind"], e.args["p"])
            elif e.kind == "override":
                p = self._captured()
                model.override(t, e.args["name"], e.args.get("value", 0), modal_v=p.V,
                               modal_a=p.A, scales_accel=self.ctx.profile.microstep is not None)
            elif e.kind == "halt":
                halts.append((e, model.halt(t)))
            elif e.kind == "go":
                model.go(t)
        last = max([r.window.hi for r in self.readings] + [e.window.hi for e in self.events])
        model.advance(last)
        return model, halts

    def _slack(self, before: int) -> int:
        """Half the width of every event window before ``before``: how far the motion may
        be shifted in time by not knowing when the unit took those frames."""
        return sum((e.window.hi - e.window.lo + 1) // 2 for e in self.events
                   if e.window.lo <= before)

    def judge(self, what: str = "") -> bool:
        """Judge every reading taken after the first event; record the trace."""
        model, halts = self.model()
        virtual = self.link.virtual
        t0 = self.events[0].window.lo if self.events else self.readings[0].window.lo
        ok_all = True
        widest = tolerance(Window(0, 0), virtual=virtual)
        for e, rest in halts:
            slack = self._slack(e.window.hi)
            a = e.answer
            ok = a.lo - slack <= rest <= a.hi + slack
            tol = tolerance(Window(a.lo - slack, a.hi + slack), virtual=virtual)
            ok_all &= self.ctx.expect(
                ok, f"{self.name}: H answered when the motion came to rest ({tol})",
                observed=f"answer at {(a.lo - t0) / 1e6:.3f} ms",
                expected=f"at rest at {(rest - t0) / 1e6:.3f} ms", rule=self.rule)
        for reading in self.readings:
            if reading.window.hi < t0:
                continue
            slack = self._slack(reading.window.hi)
            lo, hi = reading.window.lo - slack, reading.window.hi + slack
            tol = tolerance(Window(lo, hi), virtual=virtual)
            widest = max(widest, tol, key=lambda x: x.seconds)
            band = _band(model, lo, hi, tol.steps)
            got = reading.positions[:len(band)]
            ok = all(b0 <= g <= b1 for g, (b0, b1) in zip(got, band, strict=True))
            expected = [b0 + tol.steps if b0 + tol.steps == b1 - tol.steps else f"{b0}..{b1}"
                        for b0, b1 in band]
            ok_all &= self.ctx.expect(
                ok, f"{self.name}: PF at {(reading.window.lo - t0) / 1e6:.3f} ms"
                f"{' ' + reading.label if reading.label else ''} ({tol})",
                observed=got, expected=expected, rule=self.rule)
        self._trace(model, t0, widest)
        return ok_all

    def _trace(self, model: MotionModel, t0: int, tol) -> None:
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
                       tolerance=tol.as_dict(), params=dict(self.params))


def _split(body: str) -> tuple[str, str]:
    for head in ("VL", "VK", "VN", "XM", "XA", "XU", "XD"):
        if body.startswith(head):
            return head, body[len(head):]
    return body[:1], body[1:]


def _band(model: MotionModel, lo: int, hi: int, steps: int) -> list[tuple[int, int]]:
    """Per axis, the least and greatest model position over [lo, hi], widened by
    ``steps``."""
    points = [model.position(t) for t in (lo, hi, *model.boundaries(lo, hi))]
    return [(min(p[i] for p in points) - steps, max(p[i] for p in points) + steps)
            for i in range(len(points[0]))]


