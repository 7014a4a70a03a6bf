"""Checksum framing: mode toggling, good/bad/missing/lower-case sums (spec 6, 8)."""

from __future__ import annotations

from hypothesis import strategies as st
from hypothesis.stateful import rule

from conformance.case.context import CaseContext, case
from conformance.link.framing import byte_sum
from conformance.machines.as_case import run_machine
from conformance.machines.unit_machine import UnitMachine, holds, index_invariant
from gve_fixtures.protocol import ErrorCode

# bodies and the code each gets when framed correctly (spec 10, 5)
BODIES = {"V1000": ErrorCode.OK, "T5": ErrorCode.OK, "SR2": ErrorCode.OK, "A100": ErrorCode.OK,
          "Z": ErrorCode.UNKNOWN, "T99": ErrorCode.RANGE}


class ChecksumMachine(UnitMachine):
    # a frame that fails its sum, counted or not, is our reading [D]
    index_is_the_models = index_invariant("8.index.uncounted")

    @rule(on=st.booleans())
    def toggle(self, on: bool) -> None:
        r = self.send("%+" if on else "%-", checksum=self.model.checksums)
        holds(r is not None and r.ok, "6.checksum.mode-commands",
              f"%{'+' if on else '-'} answered {r}")
        holds((r.checksum is not None) == on, "6.checksum.mode-commands",
              f"response checksum presence: {r}")
        if on:
            holds(r.checksum_ok, "6.checksum.response-sum", f"bad response checksum {r}")

    @rule(body=st.sampled_from(sorted(BODIES)),
          state=st.sampled_from(["good", "bad", "missing", "lower"]))
    def command(self, body: str, state: str) -> None:
        m = self.model
        text = f"!{self.link.address}{body},".encode()
        right = "%02X" % byte_sum(text)
        sent = {"good": right, "bad": "%02X" % ((int(right, 16) + 1) % 256),
                "missing": False, "lower": right.lower()}[state]
        if not m.checksums and state != "missing":
            return               # without the mode a sum is just a bad parameter
        r = self.send(body, checksum=sent, checksum_ok=m.checksum_answer(state) == ErrorCode.OK)
        expected = BODIES[body] if m.checksum_answer(state) == ErrorCode.OK else \
            ErrorCode.SYNTAX
        # a frame with its right sum is the manual's; what a wrong one gets is ours [D]
        rule = "6.checksum.sum" if state == "good" or not m.checksums else \
            "6.checksum.bad-refused"
        holds(r is not None, rule, f"{body} ({state}) got no answer")
        holds(r.code == expected, rule,
              f"{body} with a {state} sum: code {r.code}, not {expected}")
        holds((r.checksum is not None) == m.checksums, rule, f"checksum presence in {r}")
        if m.checksums:
            holds(r.checksum_ok, "6.checksum.response-sum", f"bad response checksum in {r}")


@case("6.machine.checksum-framing",
      rules=("6.checksum.bad-refused", "6.checksum.mode-commands", "6.checksum.response-sum",
             "8.index.uncounted", "8.index.counts", "6.checksum.sum"),
      tag="M",
      requires=("%",))
def checksum_machine(ctx: CaseContext) -> None:
    """Checksum mode on/off with good, bad, missing and lower-case sums keeps its rules."""
    run_machine(ctx, ChecksumMachine)
