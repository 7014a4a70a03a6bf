"""Running a job on a unit: settings, vectors, packets, waits and checkpoints, with the
answers every one of them can get (spec 5, 7, 10.1, 10.3)."""

from __future__ import annotations

import sys
import time

from gve_fixtures.protocol import ErrorCode
from gve_host.job import Step
from gve_host.session import Session, UnitLost
from gve_host.wire import Answer

#: pause before trying a vector again after "queue full" (spec 5: try again later)
RETRY_S = 0.01
#: pause between `L0,0,0` polls while the motion runs, and between `G` tries while an
#: interrupt holds the job
POLL_S = 0.01
HOLD_POLL_S = 0.05
#: a packet refused for a member lost or damaged on the line is sent again this often
PACKET_TRIES = 5


class JobFailed(Exception):
    """The unit refused a step, or is not where the job says it must be."""


class Driver:
    def __init__(self, session: Session, *, checksums: bool = False, packets: int = 0,
                 hold_limit: float = 30.0) -> None:
        self.s = session
        self.checksums = checksums
        self.packets = packets
        self.hold_limit = hold_limit

    def run(self, steps: list[Step]) -> None:
        if self.checksums:
            self._checksums(True)
        self.s.sync()
        i = 0
        while i < len(steps):
            step = steps[i]
            if step.kind == "wait":
                self.wait_idle()
            elif step.kind == "position":
                self.checkpoint(step.position)
            elif self.packets and step.continuous:
                run = [steps[i]]
                while (len(run) < self.packets and i + len(run) < len(steps)
                       and steps[i + len(run)].continuous):
                    run.append(steps[i + len(run)])
                self.packet([s.body for s in run])
                i += len(run)
                continue
            else:
                self.command(step.body)
            i += 1
        self.wait_idle()
        if self.checksums:
            self._checksums(False)

    # -- answers ---------------------------------------------------------------------------
    def _checked(self, body: str, answer: Answer) -> Answer:
        """An answer's INTA bit: the unit stopped on an interrupt input (spec 4, 10.3)."""
        if answer.inta and not self.s.bugs.on("ignore-inta") and body != "G":
            self.hold()
        return answer

    def _checksums(self, on: bool) -> None:
        # the answer to `%+` already carries a checksum; the one to `%-` no longer does
        answer = self.s.transact("%+" if on else "%-", summed_answer=on)
        if answer is None or answer.code:
            raise JobFailed(f"checksum mode {'on' if on else 'off'} refused: {answer}")
        self.s.summed = on

    def command(self, body: str) -> None:
        """One setting or vector; a vector refused as "queue full" is tried again."""
        while True:
            answer = self.s.transact(body)
            assert answer is not None
            self._checked(body, answer)
            if answer.code == ErrorCode.QUEUE_FULL and body[:1] in ("L", "C") and not \
                    self.s.bugs.on("queue-full-ignored"):
                time.sleep(RETRY_S)
                continue
            if answer.code not in (ErrorCode.OK, ErrorCode.QUEUE_FULL):
                raise JobFailed(f"`{body}` refused: {answer}")
            return

    def packet(self, members: list[str]) -> None:
        """`*S`, the members (no answers), `*E n`: all or nothing (spec 7)."""
        tries = 0
        while tries < PACKET_TRIES:
            if self.s.index is None:
                self.s.sync()              # `@` now, not inside the packet: it would close it
            self.s.send(self.s.frame("*S"))
            for body in members:
                self.s.send(self.s.frame(body))
            start = self.s.index
            n = len(members) + (1 if self.s.bugs.on("packet-miscount") else 0)
            if start is not None:          # *S and the members count (spec 8)
                self.s.index = (start + 1 + len(members)) % 256
            answer = self.s.transact(f"*E{n}", 1, resend=False)
            if answer is None:
                continue                   # `*E` never arrived; `@` closed the packet
            self._checked("*E", answer)
            if answer.code == ErrorCode.OK or (answer.code == ErrorCode.QUEUE_FULL and
                                               self.s.bugs.on("queue-full-ignored")):
                return
            if start is not None:          # the unit counted *S, k members and *E
                self.s.index = (start + 2 + int(answer.values[0])) % 256
            if answer.code == ErrorCode.QUEUE_FULL:
                time.sleep(RETRY_S)        # queue full: try again later, as often as it takes
            elif answer.code in (ErrorCode.COUNT_MISMATCH, ErrorCode.SYNTAX):
                tries += 1                 # a member lost or damaged on the line
            else:
                raise JobFailed(f"packet {members} refused: {answer}")
        raise JobFailed(f"packet {members} failed {PACKET_TRIES} times")

    def wait_idle(self) -> None:
        """`L0,0,0` answers 1 until the motion so far has ended, then 0 (spec 10.1)."""
        while True:
            answer = self.s.transact("L0,0,0")
            assert answer is not None
            self._checked("L0,0,0", answer)
            if answer.code == ErrorCode.OK:
                return
            if answer.code != ErrorCode.QUEUE_FULL:
                raise JobFailed(f"`L0,0,0` refused: {answer}")
            time.sleep(POLL_S)

    def checkpoint(self, where: tuple[int, ...]) -> None:
        """The unit must be at ``where`` once its motion has ended."""
        if not self.s.bugs.on("early-position"):
            self.wait_idle()
        answer = self.s.transact("PF", 3)
        assert answer is not None
        here = tuple(int(v) for v in answer.values)
        if answer.code or here[: len(where)] != where:
            raise JobFailed(f"the unit is at {here}, the job says {where}")

    def hold(self) -> None:
        """Interrupted: hold until the input is released and `G` resumes (spec 10.3:
        while the input is active, `G` answers with INTA again)."""
        print("gve_host: interrupted (INTA); holding until the input is released",
              file=sys.stderr)
        deadline = time.monotonic() + self.hold_limit
        while time.monotonic() < deadline:
            time.sleep(HOLD_POLL_S)
            answer = self.s.transact("G")
            assert answer is not None
            if answer.code == ErrorCode.NOTHING_TO_GO or (answer.code == ErrorCode.OK and
                                                          not answer.inta):
                return
        raise UnitLost(f"held by an interrupt for more than {self.hold_limit:g} s")
