"""KEEP/RESTORE interleaved with motion, HALT, L moves, speed changes and GO: no step
lost or gained (spec 10.4, 10.5)."""

from __future__ import annotations

from hypothesis import strategies as st
from hypothesis.stateful import initialize, precondition, rule

from conformance.case.context import CaseContext, case
from conformance.machines.as_case import run_machine
from conformance.machines.running import Running
from conformance.machines.unit_machine import UnitMachine, holds
from gve_fixtures.protocol import ErrorCode


class KeepMachine(UnitMachine):
    """It checks the position the detours leave (at the teardown), not the index."""

    def __init__(self, ctx: CaseContext) -> None:
        super().__init__(ctx)
        # set before any rule runs: the teardown reads them even when a rule failed
        self.halted = False
        self.kept = False
        self.booked = 0         # X steps of the vectors the unit accepted in this example
        #: how long the vectors taken may run (the time account's motion)
        self.running = Running(self.link, ctx.profile.reset.V, ctx.profile.reset.A * 1000.0)

    @initialize()
    def speed(self) -> None:
        r = self.send("V2000")
        holds(r is not None and r.ok, "10.cmd.modal", f"V2000 answered {r}")
        self.running.speed = 2000

    @precondition(lambda self: not self.kept)
    @rule(steps=st.integers(200, 1500), count=st.integers(1, 3))
    def job(self, steps: int, count: int) -> None:
        for _ in range(count):
            # a real unit's guard counts a kept queue whole on top of wherever the axis
            # may be when R brings it back: the vector must fit twice over
            if not self.fits(f"C{self.booked + 2 * steps},0,0"):
                return
            r = self.send(f"C{steps},0,0")
            holds(r is not None, "10.1.queue.cont-buffer", "C got no answer")
            self.running.took(steps, r)
            if r.ok:
                self.model.book((steps, 0, 0))
                self.booked += steps

    @rule(seconds=st.sampled_from([0.05, 0.2, 0.6]))
    def run(self, seconds: float) -> None:
        self.running.wait(seconds)

    @precondition(lambda self: not self.kept)
    @rule()
    def halt(self) -> None:
        r = self.send("H")
        holds(r is not None and r.ok and r.inta, "10.4.halt.ramp", f"H answered {r}")
        self.halted = True
        self.running.halted()

    @precondition(lambda self: self.halted and not self.kept)
    @rule(lift=st.integers(1, 300))
    def keep_and_detour(self, lift: int) -> None:
        r = self.send("K")
        holds(r is not None and r.ok and not r.inta, "10.5.keep.saves", f"K answered {r}")
        self.kept, self.halted = True, False
        self.running.dropped()                # kept away from the queue
        for z in (-lift, lift):
            self.idle()
            r = self.send(f"L0,0,{z}")
            holds(r is not None and r.ok, "10.5.keep.single-l",
                  f"L0,0,{z} after K answered {r}")
        self.idle()
        self.running.at_rest()

    @precondition(lambda self: self.kept)
    @rule(speed=st.sampled_from([500, 1000, 3000]))
    def restore(self, speed: int) -> None:
        r = self.send("R")
        holds(r is not None and r.ok and r.inta, "10.5.restore.exact",
              f"R answered {r} (INTA as saved)")
        self.kept, self.halted = False, True
        self.send(f"V{speed}")
        self.send("XA")

    @precondition(lambda self: self.halted)
    @rule()
    def go(self) -> None:
        r = self.send("G")
        # with nothing left to run, 6 ("for Go, nothing to start") is allowed too (spec 5)
        holds(r is not None and r.code in (ErrorCode.OK, ErrorCode.NOTHING_TO_GO),
              "10.4.go.resume", f"G answered {r}")
        if r.code == ErrorCode.NOTHING_TO_GO:
            self.send("D")
        else:
            self.running.resumed()            # a restored queue's time is not counted
        self.halted = False

    def teardown(self) -> None:
        if self.kept:
            self.send("R")
            self.halted = True
        if self.halted:
            r = self.send("G")
            if r is not None and r.code == ErrorCode.NOTHING_TO_GO:
                self.send("D")
        self.idle()
        got = self.position()
        holds(got == self.model.committed, "10.5.restore.exact",
              f"position {got}, expected {self.model.committed}")


@case("10.5.machine.keep-restore",
      rules=("10.5.keep.saves", "10.5.restore.exact", "10.4.go.resume", "10.5.keep.single-l"),
      applies=lambda p: p.keep == "single-L" or p.keep == "full")
def keep_machine(ctx: CaseContext) -> None:
    """KEEP/RESTORE around detours with HALT, GO and XA loses and gains no step."""
    run_machine(ctx, KeepMachine)
