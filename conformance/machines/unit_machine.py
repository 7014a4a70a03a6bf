"""What every machine shares: made for its case's context, a fresh link per example,
every frame sent through :meth:`UnitMachine.send` (which books it in the model), and the
model's index check for the machines that take it as an invariant."""

from __future__ import annotations

from collections.abc import Callable

from hypothesis.stateful import RuleBasedStateMachine, invariant

from conformance.case.context import CaseContext
from conformance.link.framing import Response
from conformance.link.link import MARGIN
from conformance.model.unit import ModelUnit
from conformance.protocol.catalogue import catalogue
from conformance.protocol.parse import parse
from conformance.verdicts.quoting import as_text
from gve_fixtures.protocol import ErrorCode

#: commands whose answer ends with another frame's answer (`>`: the remembered one's)
REPEATS = frozenset(n for n, c in catalogue().items() if c.lines > 1)
#: a frame every unit refuses and none can store (no command of spec 10 begins with Z)
UNKNOWN_COMMAND = "Z"


class Broken(AssertionError):
    """A machine's invariant that failed, with the rule it checks: graded by that
    rule's tag, as a directed case's check is; what the unit did and what the rule
    wants where the machine knows them (written as a directed case's check writes them:
    conformance/verdicts/quoting.py)."""

    def __init__(self, rule: str, message: str, observed: object = None,
                 expected: object = None) -> None:
        super().__init__(message)
        self.rule = rule
        self.observed, self.expected = as_text(observed), as_text(expected)


def holds(ok: object, rule: str, message: str, *, observed: object = None,
          expected: object = None) -> None:
    """Assert ``ok`` as a check of ``rule`` (Broken when it fails)."""
    if not ok:
        raise Broken(rule, message, observed, expected)


class UnitMachine(RuleBasedStateMachine):
    """A machine on one unit: a fresh link for each example, and a model that books
    every frame sent. It keeps no invariant of its own: a machine takes the index check
    with :func:`index_invariant`."""

    def __init__(self, ctx: CaseContext) -> None:
        super().__init__()
        self.ctx = ctx
        self.link = ctx.fresh_link()
        p = ctx.profile
        # PF reports X, Y, Z on every profile (spec 10: GVE114 PF also 3 values)
        self.model = ModelUnit(axes=len(p.axes), buffer=p.buffer, committed=[0, 0, 0],
                               wire=lambda: self.link.view)
        # a real unit is not fresh: start the bookkeeping from where it is
        self.model.committed = self.position()
        self.link.read_index()          # the form the unit writes the index in, measured
        self.model.index = self.index()
        # whether @ counts itself is a reading the manuals leave open [D]: measured
        again = self.index()
        if again == (self.model.index + 1) % 256:
            self.model.uncounted = ()
        self.model.index = again
        # whether a refused frame counts is another [D]: a command no unit has (refused
        # with 3, nothing it could store) tells, judged in its own case only
        self.link.send(UNKNOWN_COMMAND)
        after = self.index()
        self.model.refused_counted = after != (again + (not self.model.uncounted)) % 256
        self.model.index = after

    def measure_packet_counting(self) -> None:
        """Whether a packet's `*S` and `*E` advance the index is a reading the manuals
        leave open (8.index.packet-frames-counted [D], judged by its case): measured on
        an empty packet (nothing to commit), then on one with a second `*S`, and the
        model counts as the unit does."""
        once = self._index_moved_by(["*S", "*E0"])
        if once in (0, 1):
            start = self._index_moved_by(["*S", "*S", "*E0"]) - once == 1
            end = once - start == 1
            self.model.uncounted = (*self.model.uncounted,
                                    *(() if start else ("*S",)), *(() if end else ("*E",)))

    def _index_moved_by(self, frames: list[str]) -> int:
        """How far ``frames`` moved the unit's index (the last one's answer awaited)."""
        before = self.index()
        for body in frames[:-1]:
            self.link.send(body, answer=False)
        self.link.send(frames[-1])
        self.model.index = self.index()
        return (self.model.index - before) % 256

    def send(self, body: str, *, checksum_ok: bool = True, **kw) -> Response | None:
        """Send ``body`` (``kw`` as :meth:`Link.send` takes them) and book its arrival in
        the model (``checksum_ok``: whether its sum lets it count)."""
        r = self.link.send(body, **kw)
        name = parse(body).name or body[:1]
        # `>` answers with the remembered frame's answer: its code refuses that frame,
        # not the `>`, which a unit counting queries has counted
        own = None if r is None or name in REPEATS else r.code
        self.model.frame_arrived(name, checksum_ok=checksum_ok, code=own)
        return r

    def fits(self, body: str) -> bool:
        """Whether a drawn motion frame keeps a real unit in its envelope: a rule skips a
        vector that does not (the emulator has no envelope: every vector fits)."""
        return self.link.guard.fits(body)

    def idle(self) -> None:
        r = self.link.poll("L0,0,0",
                           lambda r: r.code is not None and r.code != ErrorCode.QUEUE_FULL, 120,
                           send=self.send)
        holds(r is not None, "10.1.queue.wait-idiom", "the unit never became idle")
        if r.ok:
            # L0,0,0 is a normal vector to a reader of "program považuje za normální
            # vektor": its T dwell may hold RUN after it (L refused with 1 meanwhile)
            self.link.wait_idle(self.ctx.profile.range("T").hi / 1000 + 2 * MARGIN)
        # a poll that got no answer in time may still have counted: resynchronize with
        # what the unit says the index is
        self.model.index = self.index()

    def index(self) -> int:
        r = self.send("@")
        holds(r is not None and r.ok and r.values, "8.index.answer", f"@ answered {r}")
        return self.link.index_value(r)

    def position(self) -> list[int]:
        r = self.send("PF")
        holds(r is not None and r.ok, "10.cmd.positions", f"PF answered {r}")
        return r.decs()


def index_invariant(rule: str = "8.index.counts") -> Callable[[UnitMachine], None]:
    """The invariant a machine takes (``index_is_the_models = index_invariant()``) when
    every frame it sends is one the model can count: outside a packet the unit's index
    is the model's. ``rule``: the rule it checks (a machine whose frames include what
    only our reading counts names that reading's rule)."""

    @invariant()
    def index_is_the_models(self: UnitMachine) -> None:
        if self.model.packet is None:
            got = self.index()
            holds(got == self.model.index, rule, f"index {got}, model {self.model.index}")

    return index_is_the_models
