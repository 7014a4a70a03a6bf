"""What every machine shares: a fresh link per example and the model's index check."""

from __future__ import annotations

from hypothesis.stateful import RuleBasedStateMachine, invariant

from conformance.link.framing import Response
from conformance.model.unit import ModelUnit


class Broken(AssertionError):
    """A machine's invariant that failed, with the rule it checks: graded by that
    rule's tag, as a directed case's check is."""

    def __init__(self, rule: str, message: str) -> None:
        super().__init__(message)
        self.rule = rule


def holds(ok: object, rule: str, message: str) -> None:
    """Assert ``ok`` as a check of ``rule`` (Broken when it fails)."""
    if not ok:
        raise Broken(rule, message)


class UnitMachine(RuleBasedStateMachine):
    ctx = None      # set by run_machine
    #: the rule the index invariant checks (a machine whose frames include what only our
    #: reading counts names that reading's rule)
    INDEX_RULE = "8.index.counts"

    def __init__(self) -> None:
        super().__init__()
        self.link = self.ctx.fresh_link()
        p = self.ctx.profile
        # PF reports X, Y, Z on every profile (spec 10: GVE114 PF also 3 values)
        self.model = ModelUnit(axes=len(p.axes), buffer=p.buffer, committed=[0, 0, 0])
        # a real unit is not fresh: start the bookkeeping from where it is
        self.model.committed = self.position()
        self.model.index = self.index()
        # whether @ counts itself is a reading the manuals leave open [D]: measured
        again = self.index()
        if again == (self.model.index + 1) % 256:
            self.model.uncounted = ()
        self.model.index = again

    def send(self, body: str, **kw) -> Response | None:
        r = self.link.send(body, **kw)
        self.model.frame_arrived(body[:2] if body[:2] in ("*S", "*E") else body[:1])
        return r

    def fits(self, body: str) -> bool:
        """Whether a drawn motion frame keeps a real unit in its envelope: a rule skips a
        vector that does not (the emulator has no envelope: every vector fits)."""
        return self.link.guard.fits(body)

    def idle(self) -> None:
        r = self.link.poll("L0,0,0", lambda r: r.code is not None and r.code != 1, 120)
        self.model.frame_arrived("L")
        holds(r is not None, "10.1.queue.wait-idiom", "the unit never became idle")
        # the polls counted too: resynchronize with what the unit says the index is
        self.model.index = self.index()

    def index(self) -> int:
        r = self.link.send("@")
        holds(r is not None and r.code == 0 and r.values, "8.index.answer", f"@ answered {r}")
        self.model.frame_arrived("@")
        return r.dec()

    def position(self) -> list[int]:
        r = self.link.send("PF")
        self.model.frame_arrived("P")
        holds(r is not None and r.code == 0, "10.cmd.positions", f"PF answered {r}")
        return r.decs()

    @invariant()
    def index_is_the_models(self) -> None:
        if self.model.packet is None:
            got = self.index()
            holds(got == self.model.index, self.INDEX_RULE,
                  f"index {got}, model {self.model.index}")
