"""What a refused frame or a failed packet leaves behind, read back at rest: the whole
observable state (positions, ST0..ST6, F with the queue-full bit, the outputs where a rig
reads them, the index) is as it was before each one, and `>` shows the refused frame with
the answer it got (spec 4, 5, 7, 8). The modal V, A, VL and XM are read by their effect
after the refusals that would have set them (a move from rest stands where it stood
before), the queue by where G takes a halted one. The state it is refused in is built by
the machine: status words, counters, small moves, outputs, V, a queue halted with
INTA = 1."""

from __future__ import annotations

from hypothesis import strategies as st
from hypothesis.stateful import precondition, rule

from conformance.case import CaseContext, case
from conformance.link.line_band import line_band
from conformance.machines.base import UnitMachine, holds, index_invariant
from conformance.machines.runner import run_machine
from conformance.protocol.catalogue import classes
from conformance.protocol.parse import parse
from gve_fixtures.protocol import ErrorCode

IDLE, HALTED = "idle", "halted"

#: a frame refused whatever the state, or only in one: body -> (code, state, rule)
REFUSALS: dict[str, tuple[ErrorCode, str | None, str]] = {
    "Z": (ErrorCode.UNKNOWN, None, "5.code.unknown"),
    "T5,5": (ErrorCode.SYNTAX, None, "5.code.syntax"),
    "L1,2": (ErrorCode.SYNTAX, None, "5.code.syntax"),
    "T99": (ErrorCode.RANGE, None, "5.code.range"),
    "V{over}": (ErrorCode.RANGE, None, "5.code.range"),     # one above the profile's V
    "V700,5": (ErrorCode.SYNTAX, None, "5.code.syntax"),
    "A0": (ErrorCode.RANGE, None, "10.cmd.accel-range"),
    "XM0": (ErrorCode.RANGE, None, "5.code.range"),
    "VL5,5,5": (ErrorCode.RANGE, None, "10.cmd.axis-limits"),
    "SW8,F1": (ErrorCode.RANGE, None, "5.code.range"),
    "SW2,1A5": (ErrorCode.RANGE, None, "5.code.range"),
    "O0,1A5": (ErrorCode.RANGE, None, "5.code.range"),
    "G": (ErrorCode.NOTHING_TO_GO, IDLE, "5.code.nothing-to-go"),
    "L5,0,0": (ErrorCode.QUEUE_FULL, HALTED, "5.code.queue-full"),
    "N": (ErrorCode.BUSY, HALTED, "5.code.busy-run"),
    "NY5": (ErrorCode.BUSY, HALTED, "5.code.busy-run"),
}
#: the refusals only a profile with their command meets
REQUIRES = {"NY5": "NY", "XM0": "XM", "VL5,5,5": "VL"}
#: packets that fail (members, *E's n, the code): their B, C and V must leave no trace
FAILED_PACKETS = (
    (("V700", "C0,5,0"), 1, ErrorCode.COUNT_MISMATCH),   # a V that may not be a member
    (("B10", "C0,5,0", "C0,5,0"), 4, ErrorCode.COUNT_MISMATCH),
    (("C0,5,0", "V100"), 2, ErrorCode.SYNTAX),           # a member that may not be one
    (("B20", "B1", "C0,5,0"), 3, ErrorCode.RANGE),       # a member out of range
)
#: the machine's moves and halted queues (counter units on the GVE84/114; GVE54 1/16)
MOVE = st.integers(-30, 30)
#: the frame that the watchdog drops (a byte held back past its time): answered 2
STALLED = ("V500", 4)
#: the velocities the machine sets (in every profile's range; V700 is none of them)
VELOCITIES = (500, 1000, 2000)
#: V's effect: a move from rest and where it stands this long after it was sent (with the
#: reset's A every velocity above stands at its own place then, none at the move's end)
V_PROBE, V_PROBE_SECONDS = 400, 0.15
DWELL_PAST = 0.03


def _touches_motion(body: str) -> bool:
    """Whether ``body`` would set what a move from rest shows by where it stands a
    while after it was sent: V, A, VL or XM (not VK/VN, whose move runs along X)."""
    read = parse(body, strict=True)
    return read.name in classes(paces=True) and read.params[:1].isdigit()


class ReadBackMachine(UnitMachine):
    index_is_the_models = index_invariant()

    def __init__(self, ctx: CaseContext) -> None:
        super().__init__(ctx)
        self.halted = False
        self.v = ctx.profile.reset.V
        self.resumed_end: list[int] = []

    # -- the state the refusals meet ------------------------------------------------------
    @rule(word=st.integers(2, 5), value=st.integers(0, 255))
    def status(self, word: int, value: int) -> None:
        """ST2..ST5 (polarities and causes): with ST0/ST1 left 00 none of them can start
        an interrupt, whatever a real unit's inputs read."""
        r = self.send(f"SW{word},{value:02X}")
        holds(r is not None and r.ok, "10.3.status.all-bits", f"SW answered {r}")

    @precondition(lambda self: not self.halted)
    @rule(axis=st.sampled_from("XYZ"), value=st.integers(-2147483647, 2147483647))
    def counter(self, axis: str, value: int) -> None:
        if f"N{axis}" not in self.ctx.profile.commands:
            return
        r = self.send(f"N{axis}{value}")
        holds(r is not None and r.ok, "10.cmd.set-axis", f"N{axis} answered {r}")

    @precondition(lambda self: not self.halted)
    @rule(dx=MOVE, dy=MOVE, dz=MOVE)
    def move(self, dx: int, dy: int, dz: int) -> None:
        body = f"L{dx},{dy},{dz}"
        if not self.fits(body):
            return
        r = self.send(body)
        holds(r is not None and r.ok, "10.1.queue.line-alone", f"{body} answered {r}")
        self.idle()

    @rule(v=st.sampled_from(VELOCITIES))
    def velocity(self, v: int) -> None:
        r = self.send(f"V{v}")
        holds(r is not None and r.ok, "10.cmd.modal", f"V{v} answered {r}")
        self.v = v

    @rule(value=st.integers(0, 255))
    def output(self, value: int) -> None:
        """Outputs only where a rig reads them back (on a real unit they drive the
        machine's spindle and coolant)."""
        if self.link.rig is None:
            return
        r = self.send(f"O0,{value:02X}")
        holds(r is not None and r.ok, "10.cmd.output", f"O0 answered {r}")

    @precondition(lambda self: not self.halted)
    @rule()
    def halt_queue(self) -> None:
        """Two C queued and halted at once: INTA = 1, RUN = 1, the rest waiting."""
        if not (self.fits("C40,0,0") and self.fits("C80,0,0")):
            return
        for body in ("C40,0,0", "C40,0,0"):
            r = self.send(body)
            holds(r is not None and r.ok, "10.1.queue.cont-buffer", f"C answered {r}")
        ends = self.position()
        ends[0] += 80 * self.per_step()
        r = self.send("H")
        holds(r is not None and r.inta, "10.4.halt.ramp", f"H answered {r}")
        self.halted = True
        self.resumed_end = ends

    @precondition(lambda self: self.halted)
    @rule()
    def resume(self) -> None:
        """G runs what the halt left queued to its end: the two C, and nothing a refusal
        (an L answered 1, a failed packet's C) may have left in the queue."""
        r = self.send("G")
        holds(r is not None and r.ok, "10.4.go.resume", f"G after H answered {r}")
        self.halted = False
        self.idle()
        at = self.position()
        holds(at == self.resumed_end, "4.response.failed-not-executed",
              f"after G the queue ended at {at}, the two C end at {self.resumed_end}: "
              "the queue was not as the halt left it")

    def per_step(self) -> int:
        """Counter units per commanded step (the GVE54 counts sixteenths; the machine
        keeps the reset's micro-step mode)."""
        m = self.ctx.profile.microstep
        return 1 if m is None else m.factors[m.reset_mode]

    @precondition(lambda self: self.halted)
    @rule()
    def delete(self) -> None:
        r = self.send("D")
        holds(r is not None and r.ok, "10.4.delete", f"D after H answered {r}")
        self.halted = False

    # -- what a refusal leaves ------------------------------------------------------------
    def state(self) -> dict[str, object]:
        """Everything a host reads at rest (the reads count in the index as any frame).
        The position last: ST6 and F have shown the unit at rest by then, so on a real
        unit the read pins where the axes stand, which a refused packet (maybe taken as
        it arrived) leaves open until a read at rest."""
        got: dict[str, object] = {}
        for n in range(7):
            r = self.send(f"SR{n}")
            got[f"ST{n}"] = r.text if r is not None else None
        r = self.send("F")
        got["F"] = r.text if r is not None else None
        if self.link.rig is not None:
            got["outputs"] = self.link.rig.outputs()
        got["PF"] = self.position()
        return got

    def unchanged(self, before: dict[str, object], what: str, rule_id: str
                  ) -> dict[str, object]:
        """The state read back now is ``before``; returns it."""
        after = self.state()
        changed = {k: (before[k], after[k]) for k in before if before[k] != after[k]}
        holds(not changed, rule_id, f"{what} changed {changed} (before, after)")
        return after

    def repeated(self, body: str, answer: bytes) -> None:
        """`>` shows the last answered frame as received and the answer it got."""
        r = self.send(">", lines=2)
        holds(r is not None and len(r.lines) == 2, "8.repeat.answer", f"> answered {r}")
        want = [f"!{self.link.address}{body}".encode(), answer.rstrip(b"\r")]
        holds(r.lines == want, "8.repeat.remembered", f"> shows {r.lines}, expected {want}")

    def v_effect(self) -> list[int] | None:
        """Where a move from rest under the modal V stands V_PROBE_SECONDS after it was
        sent; the axis then returns to where it began. None where the move would leave
        the envelope or the queue is halted (the reading waits for a state at rest)."""
        out, back = f"L{V_PROBE},0,0", f"L{-V_PROBE},0,0"
        if self.halted or not self.fits(out):
            return None
        # past the longest dwell T after the last vector, so the move starts when sent
        self.link.wait(DWELL_PAST)
        r = self.send(out)
        holds(r is not None and r.ok, "10.1.queue.line-alone", f"{out} answered {r}")
        self.link.wait(V_PROBE_SECONDS)
        at = self.position()
        self.idle()
        r = self.send(back)
        holds(r is not None and r.ok, "10.1.queue.line-alone", f"{back} answered {r}")
        self.idle()
        return at

    def v_unchanged(self, before: list[int] | None, what: str, rule_id: str) -> None:
        """The move under V (and A, VL, XM) stands where it stood before the refusal:
        exactly in virtual
        time, within twice the line's band at V over a real line (each reading has its
        own latency)."""
        if before is None:
            return
        after = self.v_effect()
        assert after is not None
        slack = 2 * line_band(self.link.round_trip).steps(self.v * self.per_step())
        off = max(abs(a - b) for a, b in zip(after, before, strict=True))
        holds(off <= slack, rule_id, f"after {what} a move under V{self.v} stands at "
              f"{after} {V_PROBE_SECONDS} s on, before it at {before} (±{slack}): "
              "a setting of the move (V, A, VL, XM) changed")

    @rule(first=st.integers(0, len(REFUSALS) - 1))
    def refused(self, first: int) -> None:
        """Every frame refused in this state, one after the other from a drawn one on:
        each leaves the state read back as it was (the state after one is the state
        before the next), and those that would have set V, A, VL or XM leave them as a
        move under them shows, read once after them all."""
        bodies = sorted(REFUSALS)
        now = HALTED if self.halted else IDLE
        todo = [b for b in bodies[first:] + bodies[:first]
                if REFUSALS[b][1] in (None, now)
                and (b not in REQUIRES or REQUIRES[b] in self.ctx.profile.commands)]
        sent = [b.format(over=self.ctx.profile.ranges["V"].hi + 1) for b in todo]
        touching_v = [b for b in sent if _touches_motion(b)]
        reference = self.v_effect() if touching_v else None
        before = self.state()
        for key, body in zip(todo, sent, strict=True):
            want, _, code_rule = REFUSALS[key]
            r = self.send(body)
            holds(r is not None and r.code == want, code_rule, f"{body} answered {r}, "
                  f"expected code {want}")
            self.repeated(body, r.raw)
            before = self.unchanged(before, f"{body} refused with {want}",
                                    "4.response.failed-not-executed")
        self.v_unchanged(reference, f"{', '.join(touching_v)} refused",
                         "4.response.failed-not-executed")

    @rule(first=st.integers(0, len(FAILED_PACKETS) - 1))
    def failed_packet(self, first: int) -> None:
        """Every failing packet, one after the other from a drawn one on: each leaves
        the state read back as it was, those with a V leave it as a move shows."""
        if "*S" not in self.ctx.profile.commands:
            return
        packets = FAILED_PACKETS[first:] + FAILED_PACKETS[:first]
        touching_v = [p for p in packets if any(_touches_motion(m) for m in p[0])]
        reference = self.v_effect() if touching_v else None
        before = self.state()
        for members, n, want in packets:
            self.send("*S", answer=False)
            self.model.open_packet()
            for m in members:
                self.send(m, answer=False)
            self.model.packet = None
            r = self.send(f"*E{n}")
            holds(r is not None and r.code == want, "7.packet.codes",
                  f"{', '.join(members)}, *E{n} answered {r}, expected code {want}")
            self.repeated(f"*E{n}", r.raw)
            before = self.unchanged(before, f"the packet {', '.join(members)}, *E{n}",
                                    "7.packet.all-or-nothing")
        self.v_unchanged(reference, "the packets " + "; ".join(
            f"{', '.join(m)}, *E{n}" for m, n, _ in touching_v), "7.packet.all-or-nothing")

    @rule()
    def stalled(self) -> None:
        """A frame the watchdog drops: answered 2, not counted, not remembered by `>`."""
        body, at = STALLED
        before = self.state()
        before_repeat = self.link.send(">", lines=2)
        self.link.inject("host", "delay", at=at, seconds=self.ctx.profile.watchdog_ms / 1000
                         + 0.2)
        r = self.link.send(body, timeout=1.0)
        # the watchdog's time is not the manuals' (a slower one is a reading)
        holds(r is not None and r.code == ErrorCode.WATCHDOG, "3.frame.watchdog-time",
              f"{body} stalled {self.ctx.profile.watchdog_ms + 200} ms answered {r}")
        self.link.wait(0.1)                # the rest of the frame: no frame of its own
        again = self.link.send(">", lines=2)
        holds(again is not None and before_repeat is not None
              and again.lines == before_repeat.lines, "8.repeat.remembered",
              f"> after a dropped frame shows {again}, before it {before_repeat}")
        # > and the stalled frame count in the index only on a unit whose @ counts itself
        if not self.model.uncounted:
            self.model.index = (self.model.index + 2) % 256
        self.unchanged(before, f"{body} dropped by the watchdog",
                       "4.response.failed-not-executed")

    def teardown(self) -> None:
        if self.halted:
            self.send("D")


@case("4.machine.refusals-read-back",
      rules=("4.response.failed-not-executed", "7.packet.all-or-nothing", "7.packet.codes",
             "8.repeat.remembered", "8.repeat.answer", "8.index.counts", "5.code.unknown",
             "5.code.syntax", "5.code.range", "5.code.nothing-to-go", "5.code.queue-full",
             "5.code.busy-run", "3.frame.watchdog-time", "10.3.status.all-bits", "10.cmd.set-axis",
             "10.1.queue.line-alone", "10.cmd.output", "10.1.queue.cont-buffer",
             "10.4.halt.ramp", "10.4.delete", "10.cmd.modal", "10.4.go.resume",
             "10.cmd.accel-range", "10.cmd.axis-limits"))
def readback_machine(ctx: CaseContext) -> None:
    """After every refused frame and every failed packet the state read back at rest is
    as before (V, A, VL and XM by a move's effect, the queue by where G ends it); > shows
    the refused frame and its answer."""
    run_machine(ctx, ReadBackMachine)
