"""The queue, the L0,0,0 idiom, status words and F, and EEPROM round trips
(spec 10.1, 10.3, 10.6)."""

from __future__ import annotations

from hypothesis import strategies as st
from hypothesis.stateful import initialize, rule

from conformance.case.context import CaseContext, case
from conformance.machines.as_case import run_machine
from conformance.machines.unit_machine import UnitMachine, holds, index_invariant
from gve_fixtures.protocol import ErrorCode, St6

WAITING = "10.1.queue.wait-for-go"


class QueueMachine(UnitMachine):
    index_is_the_models = index_invariant()

    def __init__(self, ctx: CaseContext) -> None:
        super().__init__(ctx)
        # set before any rule runs: the teardown reads them even when a rule failed
        self.queued = 0
        self.status: dict[int, int] = {}
        self.eeprom: dict[int, int] = {}

    @initialize()
    def interrupted(self) -> None:
        # vectors wait in the queue while INTA = 1 [D 10.1]: the queue length is ours
        r = self.send("H")
        holds(r is not None and r.inta, "4.response.inta-bit", f"H answered {r}")

    @rule(count=st.integers(1, 40))
    def queue(self, count: int) -> None:
        for i in range(count):
            r = self.send("C" + ("1,0,0" if i % 2 == 0 else "-1,0,0"))
            full = self.queued >= self.model.buffer
            # the count of queued vectors rests on their waiting while INTA = 1 [D]
            holds(r is not None
                  and r.code == (ErrorCode.QUEUE_FULL if full else ErrorCode.OK), WAITING,
                  f"C with {self.queued} queued of {self.model.buffer}: {r}")
            if not full:
                self.queued += 1

    @rule()
    def wait_idiom(self) -> None:
        r = self.send("L0,0,0")
        holds(r is not None
              and r.code == (ErrorCode.QUEUE_FULL if self.queued else ErrorCode.OK), WAITING,
              f"L0,0,0: {r}")
        if r.ok:
            self.queued += 1            # accepted while INTA = 1: it waits for G [D 10.1]

    @rule()
    def delete(self) -> None:
        r = self.send("D")
        holds(r is not None and r.ok, "5.code.ok", f"D answered {r}")
        self.queued = 0
        self.status.update({4: 0, 5: 0})    # D clears ST4..ST6 (spec 10.4)
        r = self.send("H")                  # interrupted again, so vectors stay queued
        holds(r is not None and r.inta, "4.response.inta-bit", f"H answered {r}")

    @rule(n=st.sampled_from([3, 4, 5]), value=st.integers(0, 255))
    def status_word(self, n: int, value: int) -> None:
        r = self.send("SW%d,%02X" % (n, value))
        holds(r is not None and r.ok, "10.cmd.status-words", f"SW{n} answered {r}")
        self.status[n] = value
        r = self.send(f"SR{n}")
        holds(r is not None and r.values == ["%02X" % value], "10.cmd.status-words",
              f"SR{n}: {r}")

    @rule(address=st.integers(0x40, 0x47), value=st.integers(0, 255))
    def eeprom_write(self, address: int, value: int) -> None:
        r = self.send("EW%02X,%02X" % (address, value))
        holds(r is not None and r.ok, "10.cmd.eeprom-bytes", f"EW answered {r}")
        self.eeprom[address] = value

    def flags(self) -> None:
        r = self.send("F")
        holds(r is not None and r.ok and r.values, "10.cmd.flags", f"F answered {r}")
        full = St6.QUEUE_FULL if self.queued >= self.model.buffer else 0
        run = St6.RUN if self.queued else 0
        holds(r.hex() & (St6.QUEUE_FULL | St6.RUN) == full | run, WAITING,
              f"F = {r.values[0]}, {self.queued} of {self.model.buffer} queued")

    def teardown(self) -> None:
        self.flags()
        for address, value in self.eeprom.items():
            r = self.send("ER%02X" % address)
            holds(r is not None and r.values == ["%02X" % value], "10.cmd.eeprom-bytes",
                  f"ER{address:02X}: {r}")
        for n, value in self.status.items():
            r = self.send(f"SR{n}")
            holds(r is not None and r.values == ["%02X" % value], "10.cmd.status-words",
                  f"SR{n}: {r}")


@case("10.machine.queue-status-eeprom",
      rules=("10.1.queue.cont-buffer", "10.1.queue.wait-idiom", "10.cmd.flags",
             "10.cmd.status-words", "10.cmd.eeprom-bytes", "10.1.queue.wait-for-go",
             "4.response.inta-bit", "5.code.ok"),
      destructive=True)
def queue_machine(ctx: CaseContext) -> None:
    """The queue's room, L0,0,0, F, status words and EEPROM bytes keep their rules."""
    run_machine(ctx, QueueMachine)
