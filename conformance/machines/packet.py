"""Packets *S/*E: member counts right and wrong, invalid members, breakers (spec 7)."""

from __future__ import annotations

from hypothesis import strategies as st
from hypothesis.stateful import initialize, precondition, rule

from conformance.case.context import CaseContext, case
from conformance.machines.as_case import run_machine
from conformance.machines.unit_machine import UnitMachine, holds, index_invariant
from gve_fixtures.protocol import ErrorCode

# member frame -> (kind, code it fails the packet with, steps it commits)
MEMBERS = {"C1,0,0": ("C", ErrorCode.OK, (1, 0, 0)), "C0,2,0": ("C", ErrorCode.OK, (0, 2, 0)),
           "B500": ("B", ErrorCode.OK, None), "B1": ("B", ErrorCode.RANGE, None),
           "V100": ("V", ErrorCode.SYNTAX, None), "C1,2": ("C", ErrorCode.SYNTAX, None)}


class PacketMachine(UnitMachine):
    index_is_the_models = index_invariant()

    def __init__(self, ctx: CaseContext) -> None:
        super().__init__(ctx)
        self.pending: list[str] = []          # the members sent since *S
        self.measure_packet_counting()

    @initialize(summed=st.booleans())
    def mode(self, summed: bool) -> None:
        if summed:
            r = self.send("%+", checksum=False)
            holds(r is not None and r.ok, "6.checksum.mode-commands", f"%+ answered {r}")

    @rule()
    def start(self) -> None:
        self.send("*S", answer=False)
        self.model.open_packet()              # a second *S restarts the packet (spec 7)
        self.pending = []

    @precondition(lambda self: self.model.packet is not None and len(self.model.packet) < 8)
    @rule(body=st.sampled_from(sorted(MEMBERS)))
    def member(self, body: str) -> None:
        self.send(body, answer=False)
        kind, code, _ = MEMBERS[body]
        self.model.member(kind, code)
        self.pending = [*self.pending, body]

    @rule(delta=st.sampled_from([0, 0, 0, 1, -1]))
    def end(self, delta: int) -> None:
        members = list(self.pending) if self.model.packet is not None else []
        k = len(self.model.packet) if self.model.packet is not None else 0
        n = max(0, k + delta)
        expected = self.model.end_packet(n, self.model.buffer)
        r = self.send(f"*E{n}")
        self.pending = []
        holds(r is not None, "7.packet.exchange", "*E got no answer")
        holds((r.code, r.values) == (expected[0], [str(expected[1])]), "7.packet.codes",
              f"*E{n}: {r.text}, expected {expected[0]},{expected[1]}")
        if expected[0] == ErrorCode.OK:
            for body in members:
                steps = MEMBERS[body][2]
                if steps:
                    self.model.book(steps)

    @precondition(lambda self: self.model.packet is not None)
    @rule()
    def breaker(self) -> None:
        r = self.send("@")
        holds(r is not None and r.ok, "7.packet.breakers",
              f"@ inside a packet answered {r}")
        self.pending = []                 # answered, `@` ended the packet on the wire
        # That `@` discards the packet is our reading [D]: the manual only says the unit
        # answers once the packet's end arrives. A unit that keeps it open would take every
        # frame after as a member and answer none, so an `*E0` ends it under either reading
        # (`4,0`: there was none) before the machine goes on.
        r = self.send("*E0")
        holds(r is not None and r.code == ErrorCode.SYNTAX, "7.packet.breakers",
              f"*E0 after @ inside a packet answered {r}: the packet was still open",
              observed=r, expected="4,0")

    def teardown(self) -> None:
        if self.model.packet is None:
            self.idle()
            got = self.position()
            holds(got == self.model.committed, "7.packet.all-or-nothing",
                  f"position {got}, committed {self.model.committed}")


@case("7.machine.packets",
      rules=("7.packet.all-or-nothing", "7.packet.codes", "7.packet.exchange",
             "7.packet.checksums", "7.packet.breakers"),
      requires=("*S",))
def packet_machine(ctx: CaseContext) -> None:
    """Packets commit all or nothing, answer code,k, with and without checksums."""
    run_machine(ctx, PacketMachine)
