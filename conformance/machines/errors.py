"""Error codes 0-7 and the INTA bit, each provoked from the states where it arises:
idle, moving, and interrupted with the rest queued (spec 4, 5)."""

from __future__ import annotations

from hypothesis import strategies as st
from hypothesis.stateful import rule

from conformance.case.context import CaseContext, case
from conformance.machines.as_case import run_machine
from conformance.machines.running import Running
from conformance.machines.unit_machine import UnitMachine, holds, index_invariant
from conformance.protocol.catalogue import classes
from gve_fixtures.protocol import ErrorCode, St6

RUN, INTA = St6.RUN, St6.INTA


def expected_code(body: str, moving: bool, run: bool, inta: bool) -> ErrorCode:
    """The code of spec 5 for ``body`` in a state (moving; RUN; INTA)."""
    table = {"V1000": ErrorCode.OK, "T99": ErrorCode.RANGE, "Z": ErrorCode.UNKNOWN,
             "V+1": ErrorCode.SYNTAX, "SW8,F1": ErrorCode.RANGE, "F": ErrorCode.OK,
             "SR6": ErrorCode.OK, "C1,0,0": ErrorCode.OK, "A0": ErrorCode.RANGE,
             "T5,5": ErrorCode.SYNTAX}
    if body == "N":
        return ErrorCode.BUSY if run else ErrorCode.OK
    if body in classes(still=True):
        return ErrorCode.BUSY if moving else ErrorCode.OK
    if body == "G":
        return ErrorCode.OK if inta else ErrorCode.NOTHING_TO_GO
    if body == "L0,0,0":
        return ErrorCode.QUEUE_FULL if run else ErrorCode.OK
    return table[body]


#: the rule each code checks; a probe whose code is our reading names that reading
CODE_RULE = {ErrorCode.OK: "5.code.ok", ErrorCode.QUEUE_FULL: "10.1.queue.wait-idiom",
             ErrorCode.UNKNOWN: "5.code.unknown", ErrorCode.SYNTAX: "5.code.syntax",
             ErrorCode.RANGE: "5.code.range", ErrorCode.NOTHING_TO_GO: "5.code.nothing-to-go",
             ErrorCode.BUSY: "5.code.busy-moving"}
CODE_RULES = {"V+1": "3.params.decimal", "A0": "10.cmd.accel-range", "N": "5.code.busy-run"}


class ErrorMachine(UnitMachine):
    index_is_the_models = index_invariant()

    def __init__(self, ctx: CaseContext) -> None:
        super().__init__(ctx)
        reset = ctx.profile.reset
        #: how long the vectors taken may run (the time account's motion)
        self.running = Running(self.link, reset.V, reset.A * 1000.0)

    def observe(self) -> tuple[bool, bool, bool]:
        r = self.send("SR6")
        holds(r is not None and r.ok and r.values, "10.cmd.status-words",
              f"SR6 answered {r}")
        st6 = r.hex()
        holds(r.inta == bool(st6 & INTA), "4.response.inta-bit",
              f"the INTA bit of {r.text} disagrees with ST6")
        inta, run = bool(st6 & INTA), bool(st6 & RUN)
        moving = (run and not inta) or bool(st6 & St6.STOP)
        if not moving:
            self.running.at_rest()
        return moving, run, inta

    @rule(steps=st.integers(500, 1500))
    def motion(self, steps: int) -> None:
        if not self.fits(f"C{steps},0,0"):
            return
        r = self.send(f"C{steps},0,0")
        holds(r is not None and r.code in (ErrorCode.OK, ErrorCode.QUEUE_FULL),
              "10.1.queue.cont-buffer", f"C answered {r}")
        self.running.took(steps, r)

    @rule()
    def halt(self) -> None:
        r = self.send("H")
        holds(r is not None and r.ok and r.inta, "4.response.inta-bit",
              f"H answered {r}")
        self.running.halted()

    @rule(seconds=st.sampled_from([0.01, 0.3, 1.5]))
    def wait(self, seconds: float) -> None:
        self.running.wait(seconds)

    @rule(body=st.sampled_from(["V1000", "T99", "Z", "V+1", "SW8,F1", "F", "SR6", "C1,0,0",
                                "A0", "T5,5", "N", "D", "G", "L0,0,0"]))
    def probe(self, body: str) -> None:
        moving, run, inta = self.observe()
        if body == "C1,0,0" and not inta:
            return                      # would start motion the model cannot time
        r = self.send(body)
        want = expected_code(body, moving, run, inta)
        holds(r is not None, "5.code.ok", f"{body} got no answer")
        # G with INTA = 1 and nothing pending may answer 6 as well (spec 5, both readings)
        also = {ErrorCode.NOTHING_TO_GO} if body == "G" and inta and not run else set()
        allowed = {want} | also
        holds(r.code in allowed, CODE_RULES.get(body, CODE_RULE.get(want, "5.code.ok")),
              f"{body} (moving={moving}, RUN={run}, INTA={inta}): code {r.code}, "
              f"expected {want}")
        after = {"G": False, "D": False}.get(body, inta) if r.ok else inta
        if body == "V1000" and r.ok:
            self.running.speed = 1000
        elif body == "G" and r.ok:
            self.running.resumed()
        elif body == "D" and r.ok:
            self.running.dropped()
        if r.code == ErrorCode.NOTHING_TO_GO and inta:
            self.send("D")                  # nothing started: clear INTA the manual's way
            after = r.inta
        holds(r.inta == after, "4.response.inta-after-command",
              f"{body}: INTA bit {r.inta}, expected {after}")


@case("5.machine.error-codes",
      rules=("5.code.nothing-to-go", "5.code.busy-moving", "5.code.busy-run", "5.code.unknown",
             "5.code.syntax", "5.code.range", "4.response.inta-bit",
             "4.response.inta-after-command", "5.code.ok", "3.params.decimal",
             "10.cmd.accel-range", "10.1.queue.wait-idiom", "10.1.queue.cont-buffer",
             "10.cmd.status-words"))
def error_machine(ctx: CaseContext) -> None:
    """Each error code arises exactly in its states, with the INTA bit of ST6."""
    run_machine(ctx, ErrorMachine)
