"""Index/repeat recovery with fault injection: lost commands, lost or corrupted
responses, recovered with @ and > so that no vector runs twice or is skipped (spec 8)."""

from __future__ import annotations

from hypothesis import strategies as st
from hypothesis.stateful import rule

from conformance.case.context import CaseContext, case
from conformance.machines.as_case import run_machine
from conformance.machines.unit_machine import UnitMachine, holds

FAULTS = {"none": None, "lost-command": ("host", "drop", {}),
          "lost-response": ("unit", "drop", {}),
          "corrupt-response": ("unit", "corrupt", {"at": 0, "xor": 0x40})}


class RecoveryMachine(UnitMachine):
    """It checks the positions each recovery leaves, not the index (a recovery reads
    the index itself: a frame a fault dropped did not count)."""

    repeated = False        # whether a recovery in this example used >

    @rule(axis=st.integers(0, 2), steps=st.integers(-40, 40).filter(bool),
          fault=st.sampled_from(sorted(FAULTS)))
    def vector(self, axis: int, steps: int, fault: str) -> None:
        move = [0, 0, 0]
        move[axis] = steps
        body = "L" + ",".join(map(str, move))
        before = self.index()
        if FAULTS[fault]:
            direction, kind, params = FAULTS[fault]
            self.link.inject(direction, kind, **params)
        r = self.send(body)
        if r is not None and r.well_formed and r.ok:
            self.model.book(tuple(move))
        else:
            self.recover(body, move, before)
        self.idle()
        got = self.position()
        # booked by what > showed, the position judges our reading of > as well [D]
        holds(got == self.model.committed, "8.repeat.answer" if self.repeated else
              "8.index.counts", f"position {got}, expected {self.model.committed}")

    def recover(self, body: str, move: list[int], before: int) -> None:
        """The host's recovery rule of spec 8: ask @; if the command arrived, > shows
        its answer; resend only if it did not arrive or was refused."""
        # the @ that reads the index counts itself on a unit whose @ counts (measured) [D]
        counted = "@" not in self.model.uncounted
        arrived = self.index() == (before + 1 + counted) % 256
        if arrived:
            r = self.send(">", lines=2)
            self.repeated = True
            holds(r is not None and r.lines, "8.repeat.answer", "> got no answer")
            # > showing the @ just sent: that @ is never remembered is our reading [D]
            shown = r.lines[0]
            holds(shown == f"!{self.link.address}{body}".encode(),
                  "8.repeat.remembered" if shown == f"!{self.link.address}@".encode()
                  else "8.repeat.answer", f"> shows {shown!r}, not the last frame {body}")
            if r.ok:
                self.model.book(tuple(move))
                return
        self.idle()
        r = self.send(body)
        holds(r is not None and r.ok, "8.index.counts", f"resent {body}: {r}")
        self.model.book(tuple(move))


@case("8.machine.recovery",
      rules=("8.index.counts", "8.repeat.answer", "8.repeat.remembered"))
def recovery_machine(ctx: CaseContext) -> None:
    """Lost commands and lost/corrupted responses are recovered with @ and > exactly
    once."""
    run_machine(ctx, RecoveryMachine)
