"""What a refused frame or a failed packet leaves behind, read back at rest: the whole
observable state (positions, ST0..ST6, F with the queue-full bit, the outputs and the
GVE114's spindle where a rig reads them, the index) is as it was before each one, and `>`
shows the refused frame with the answer it got (spec 4, 5, 7, 8, 12). What the refusals
would have set is read by its effect after them, compared with the same reading before
them: V, A, VL and XM by where a move from rest stands a while after it was sent, B by
where a continuous path of two C stands as it passes their junction, T by where a move
started right after another ended stands (the dwell between them), the GVE54's
micro-step mode by how far one commanded step goes; the queue by where G takes a halted
one. The state it is refused in is built by the machine: status words, counters, small
moves, outputs, V, the spindle, a queue halted with INTA = 1."""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass
from typing import NamedTuple

from hypothesis import strategies as st
from hypothesis.stateful import precondition, rule

from conformance.case.context import CaseContext, case
from conformance.link.framing import Response
from conformance.link.line_band import line_band
from conformance.link.link import idle_st6
from conformance.machines.as_case import run_machine
from conformance.machines.unit_machine import UnitMachine, holds, index_invariant
from conformance.protocol.catalogue import catalogue, classes
from conformance.protocol.parse import parse
from gve_fixtures.profile import Profile
from gve_fixtures.protocol import SECOND, ErrorCode
from gve_fixtures.rules import load_rules

IDLE, HALTED = "idle", "halted"
#: the address a refusal goes to: the unit's own, or the GVE114's spindle (spec 12)
UNIT, SPINDLE = "unit", "spindle"


class Refusal(NamedTuple):
    """A frame refused whatever the state, or only in ``state``: the code it gets and the
    rule that code is checked by (None: the rule the catalogue names for the command's
    range on the profile, as a V or B out of range is the GVE54's [M] and the others' [D])."""

    body: str                 # {over}: one above the profile's V; {spindle_over}: its !7V
    code: ErrorCode
    rule: str | None = None
    state: str | None = None
    address: str = UNIT
    #: other codes a reading allows, its [D] choice graded in its own case
    also: tuple[ErrorCode, ...] = ()


E = ErrorCode
#: a hex field of three digits: range-checked (5), or to a reader of the manuals' 00..FF
#: a syntax error (4; 3.params.hex-digits)
LONG_HEX = (ErrorCode.SYNTAX,)
#: every frame the machine has refused, in the order it tries them
REFUSALS: tuple[Refusal, ...] = (
    Refusal("A0", E.RANGE, "10.cmd.accel-range"),
    Refusal("B5", E.RANGE),                          # below every profile's B
    Refusal("B700,5", E.SYNTAX, "5.code.syntax"),
    Refusal("G", E.NOTHING_TO_GO, "5.code.nothing-to-go", IDLE),
    # more components than any unit has axes (fewer may be taken with the rest 0: a
    # reading); every number readable, so a guard can bound it
    Refusal("L1,2,3,4,5", E.SYNTAX, "5.code.syntax"),
    Refusal("L5,0,0", E.QUEUE_FULL, "5.code.queue-full", HALTED),
    Refusal("M4,5", E.SYNTAX, "5.code.syntax"),      # a stored 4 would move 4 sixteenths
    Refusal("N", E.BUSY, "5.code.busy-run", HALTED),
    Refusal("NY5", E.BUSY, "5.code.busy-run", HALTED),
    Refusal("O0,1A5", E.RANGE, "5.code.range", also=LONG_HEX),
    Refusal("SW2,1A5", E.RANGE, "5.code.range", also=LONG_HEX),
    Refusal("SW8,F1", E.RANGE, "5.code.range"),
    Refusal("T0", E.RANGE),
    Refusal("T20,5", E.SYNTAX, "5.code.syntax"),     # a stored 20 would lengthen the dwell
    Refusal("T99", E.RANGE, "5.code.range"),
    Refusal("V700,5", E.SYNTAX, "5.code.syntax"),
    Refusal("V{over}", E.RANGE),
    Refusal("VL5,5,5", E.RANGE, "10.cmd.axis-limits"),
    Refusal("XM0", E.RANGE, "5.code.range"),
    Refusal("Z", E.UNKNOWN, "5.code.unknown"),
    Refusal("V{spindle_over}", E.RANGE, "12.spindle.speed", address=SPINDLE),
    Refusal("V5,5", E.SYNTAX, "5.code.syntax", address=SPINDLE),
)
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
#: the spindle speeds the machine sets where a rig reads them (per mille, spec 12)
SPINDLE_SPEEDS = st.integers(0, 1000)
#: V's effect: a move from rest and where it stands this long after it was sent (with the
#: reset's A every velocity above stands at its own place then, none at the move's end)
V_PROBE, V_PROBE_SECONDS = 400, 0.15
#: B's effect: two C of this length from rest, read this long after the first was sent
#: (n < $: each cruises at B if B is below V, and leaves the junction at B)
JUNCTION_LEG, JUNCTION_SECONDS = 200, 0.15
#: T's effect: a move, F read until it ended, then the way back, read this long after
DWELL_PROBE, DWELL_SECONDS = 40, 0.05
DWELL_PAST = 0.03
#: real time: how many times more an effect that reads off is read before it fails
REREADS = 1


@dataclass(frozen=True)
class Effect:
    """How the machine reads back what refused frames of some commands would set."""

    probe: str          # the machine's method reading it (None where it cannot now)
    setting: str        # what it reads, and the settings it depends on
    timed: bool = True  # read at an instant: within the line's band in real time
    polled: bool = False   # its instant follows a poll: one round trip more in real time


#: the effects the machine reads, in the order it reads them after the refusals
EFFECTS = {
    "microstep": Effect("microstep_effect", "one commanded step (the micro-step mode)",
                        timed=False),
    "pace": Effect("v_effect", "a move from rest (V, A, VL, XM; B where below V, the "
                   "move being shorter than $)"),
    "junction": Effect("junction_effect", "two C through their junction (B; V, A, VL, XM)"),
    "dwell": Effect("dwell_effect", "a move taken as the one before it ended (T; V, A, "
                    "VL, XM)", polled=True),
}
#: the commands answered when their motion has stopped: no round trip of the line
DEFERRED = classes(deferred=True)
#: the commands whose value a refused frame must not set -> the effect that shows it
EFFECT_OF = {**{name: "pace" for name in classes(paces=True)},
             "B": "junction", "T": "dwell", "M": "microstep"}


def effect_of(body: str) -> str | None:
    """The effect that shows what ``body`` (at the unit's address) would set, if any: a
    value or a mode follows its command (VK and VN set nothing of a move along X, a
    signed `V+1` is no value)."""
    read = parse(body, strict=True)
    return EFFECT_OF.get(read.name or "") if read.params[:1].isalnum() else None


def range_rule(body: str, profile: Profile) -> str:
    """The rule the catalogue names for ``body``'s command out of range on ``profile``:
    its first that applies there, else 5.code.range."""
    known = load_rules()
    command = catalogue()[parse(body, strict=True).name or ""]
    return next((r for r in command.rules
                 if known[r].applies_to(profile.name, profile.family)), "5.code.range")


class ReadBackMachine(UnitMachine):
    index_is_the_models = index_invariant()

    def __init__(self, ctx: CaseContext) -> None:
        #: ms: the round trips of the frames answered at once since the effects were
        #: last read before refusals (the line as the readings saw it, line_band's jitter)
        self.trips: list[float] = []
        super().__init__(ctx)
        if "*S" in ctx.profile.commands:
            self.measure_packet_counting()
        self.halted = False
        self.v = ctx.profile.reset.V
        self.resumed_end: list[int] = []

    def send(self, body: str, **kw) -> Response | None:
        """:meth:`UnitMachine.send`, keeping the round trip of a frame answered at once."""
        r = super().send(body, **kw)
        if r is not None and parse(body).name not in DEFERRED:
            self.trips.append((r.received_at - r.sent_at) / 1e6)
        return r

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

    @precondition(lambda self: self.link.rig is not None)
    @rule(value=st.integers(0, 255))
    def output(self, value: int) -> None:
        """Outputs only where a rig reads them back (on a real unit they drive the
        machine's spindle and coolant)."""
        r = self.send(f"O0,{value:02X}")
        holds(r is not None and r.ok, "10.cmd.output", f"O0 answered {r}")

    @precondition(lambda self: self.link.rig is not None
                  and self.ctx.profile.spindle is not None)
    @rule(value=SPINDLE_SPEEDS)
    def spindle(self, value: int) -> None:
        """The GVE114's spindle, only where a rig reads it back (on a real unit it turns
        the machine's spindle)."""
        r = self.send(f"V{value}", address=self.ctx.profile.spindle.address)
        holds(r is not None and r.ok, "12.spindle.speed", f"!7V{value} answered {r}")

    @precondition(lambda self: not self.halted)
    @rule()
    def halt_queue(self) -> None:
        """Two C queued and halted at once: INTA = 1, RUN = 1, the rest waiting; the
        frames refused only then are refused at once."""
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
        # what only a halted queue refuses, at once: the queue they must leave as it was
        # is read where G takes it (resume, or the example's end)
        self.refuse([r for r in REFUSALS if r.state == HALTED and self.meets(r)])

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
            if self.ctx.profile.spindle is not None:
                got["spindle"] = self.link.rig.spindle()
        got["PF"] = self.position()
        return got

    def unchanged(self, before: dict[str, object], what: str, rule_id: str
                  ) -> dict[str, object]:
        """The state read back now is ``before``; returns it."""
        after = self.state()
        changed = {k: (before[k], after[k]) for k in before if before[k] != after[k]}
        holds(not changed, rule_id, f"{what} changed {changed} (before, after)")
        return after

    def repeated(self, body: str, answer: bytes, address: int | None = None) -> None:
        """`>` (at ``address``, else the unit's) shows the last answered frame there as
        received and the answer it got."""
        address = self.link.address if address is None else address
        r = self.send(">", lines=2, address=address)
        holds(r is not None and len(r.lines) == 2, "8.repeat.answer", f"> answered {r}")
        want = [f"!{address}{body}".encode(), answer.rstrip(b"\r")]
        holds(r.lines == want, "8.repeat.remembered", f"> shows {r.lines}, expected {want}")

    # -- the effects of the settings ------------------------------------------------------
    def at_rest(self, out: str) -> bool:
        """Whether a probe may run: the queue not halted (a reading waits for a state at
        rest) and its move out within the envelope."""
        return not self.halted and self.fits(out)

    def settled(self, body: str, rule_id: str) -> Response:
        """Send ``body``, which the unit must take (answer 0)."""
        r = self.send(body)
        holds(r is not None and r.ok, rule_id, f"{body} answered {r}")
        assert r is not None
        return r

    def v_effect(self) -> list[int] | None:
        """Where a move from rest under the modal V stands V_PROBE_SECONDS after it was
        sent; the axis then returns to where it began."""
        out = f"L{V_PROBE},0,0"
        if not self.at_rest(out):
            return None
        # past the longest dwell T after the last vector, so the move starts when sent
        self.link.wait(DWELL_PAST)
        self.settled(out, "10.1.queue.line-alone")
        self.link.wait(V_PROBE_SECONDS)
        return self._read_and_return(f"L{-V_PROBE},0,0")

    def junction_effect(self) -> list[int] | None:
        """Where a path of two C from rest stands JUNCTION_SECONDS after the first was
        sent: with B at or above V it runs through their junction at V, with a lower B it
        slows to B there (and, each shorter than $, cruises at B)."""
        if not self.at_rest(f"L{2 * JUNCTION_LEG},0,0"):
            return None
        self.link.wait(DWELL_PAST)
        first = self.settled(f"C{JUNCTION_LEG},0,0", "10.1.queue.cont-buffer")
        self.settled(f"C{JUNCTION_LEG},0,0", "10.1.queue.cont-buffer")
        # the read's instant counts from the first C, as the motion does
        self.link.wait(max(0.0, JUNCTION_SECONDS - (self.link.now - first.sent_at) / SECOND))
        return self._read_and_return(f"L{-2 * JUNCTION_LEG},0,0")

    def _read_and_return(self, back: str) -> list[int]:
        """The axes' position now; once at rest, ``back`` takes them where they began."""
        at = self.position()
        self.idle()
        self.settled(back, "10.1.queue.line-alone")
        self.idle()
        return at

    def dwell_effect(self) -> list[int] | None:
        """Where the way back of a move stands DWELL_SECONDS after it was sent, as soon
        as F showed the move out ended (F read back to back): it starts T after that end,
        or when it arrived if that is later."""
        out, back = f"L{DWELL_PROBE},0,0", f"L{-DWELL_PROBE},0,0"
        if not self.at_rest(out):
            return None
        self.link.wait(DWELL_PAST)
        self.settled(out, "10.1.queue.line-alone")
        r = self.link.poll("F", lambda r: r.ok and idle_st6(r), 30, every=0.0,
                           send=self.send)
        holds(r is not None, "10.3.st6.bits", f"F never showed the move {out} ended")
        self.settled(back, "10.1.queue.line-alone")
        self.link.wait(DWELL_SECONDS)
        at = self.position()
        self.idle()
        return at

    def microstep_effect(self) -> list[int] | None:
        """How many counter units one commanded step moves the X axis (spec 10.7: 8, 4, 2,
        1 sixteenths in M2, M4, M8, MF); it then steps back."""
        if self.ctx.profile.microstep is None or not self.at_rest("L1,0,0"):
            return None
        start = self.position()
        self.settled("L1,0,0", "10.1.queue.line-alone")
        self.idle()
        moved = self.position()[0] - start[0]
        self.settled("L-1,0,0", "10.1.queue.line-alone")
        self.idle()
        return [moved]

    def effects(self, touched: set[str]) -> dict[str, list[int] | None]:
        """The readings of the ``touched`` effects, in EFFECTS' order."""
        return {name: getattr(self, e.probe)() for name, e in EFFECTS.items()
                if name in touched}

    def slack(self, effect: Effect) -> int:
        """Counter units two readings of ``effect`` may differ by on a correct unit: none
        in virtual time or when not timed; over a real line twice the line's band at V
        (each reading has its own latency), its jitter that of the round trips since the
        readings before, and the slowest round trip more after a poll."""
        if not effect.timed or self.link.virtual:
            return 0
        rate = self.v * self.per_step()
        band = line_band(self.link.round_trip, self.trips)
        polled = max([self.link.round_trip.get("max_ms", 0.0), *self.trips]) / 1e3 \
            if effect.polled else 0.0
        return 2 * band.steps(rate) + math.ceil(rate * polled)

    def effects_unchanged(self, before: dict[str, list[int] | None], what: str,
                          rule_id: str) -> None:
        """Each effect read before ``what`` reads the same now: exactly in virtual time,
        within :meth:`slack` over a real line, where a reading off by more is taken
        again (a line or a host that stalled once moves a reading by tens of ms: a
        stored setting reads off again)."""
        for name, was in before.items():
            if was is None:
                continue
            effect = EFFECTS[name]
            readings: list[list[int]] = []
            for _ in range(1 if self.link.virtual else REREADS + 1):
                now = getattr(self, effect.probe)()
                assert now is not None
                readings.append(now)
                if self.off(now, was) <= self.slack(effect):
                    break
            slack = self.slack(effect)
            holds(self.off(readings[-1], was) <= slack, rule_id,
                  f"after {what} {effect.setting} under V{self.v} reads "
                  f"{' then '.join(map(str, readings))}, before them {was} (±{slack}): "
                  "a setting changed")

    @staticmethod
    def off(now: list[int], was: list[int]) -> int:
        return max(abs(a - b) for a, b in zip(now, was, strict=True))

    # -- the refusals ---------------------------------------------------------------------
    def meets(self, refusal: Refusal) -> bool:
        """Whether the profile (and the link) take ``refusal``'s frame here: its command
        is the profile's, and the spindle's refusals only where a rig reads the spindle
        (on a real unit a wrongly stored speed would start it)."""
        if refusal.address == SPINDLE:
            return self.ctx.profile.spindle is not None and self.link.rig is not None
        name = parse(refusal.body, strict=True).name
        command = catalogue().get(name or "")
        return command is None or command.known_as in self.ctx.profile.commands

    def address(self, refusal: Refusal) -> int:
        spindle = self.ctx.profile.spindle
        return spindle.address if refusal.address == SPINDLE and spindle is not None \
            else self.link.address

    def body(self, refusal: Refusal) -> str:
        p = self.ctx.profile
        return refusal.body.format(
            over=p.ranges["V"].hi + 1,
            spindle_over=p.spindle.range.hi + 1 if p.spindle is not None else 0)

    @rule(first=st.integers(0, len(REFUSALS) - 1))
    def refused(self, first: int) -> None:
        """Every frame refused in this state, one after the other from a drawn one on."""
        now = HALTED if self.halted else IDLE
        self.refuse([r for r in REFUSALS[first:] + REFUSALS[:first]
                     if r.state in (None, now) and self.meets(r)])

    def refuse(self, todo: list[Refusal]) -> None:
        """Send each of ``todo``: each leaves the state read back as it was (the state
        after one is the state before the next), and what those that would have set V,
        A, VL, XM, B, T or the micro-step mode would have set reads as before, read once
        after them all."""
        sent = [self.body(r) for r in todo]
        touched = {effect_of(b) for r, b in zip(todo, sent, strict=True)
                   if r.address == UNIT} - {None}
        self.trips = []
        reference = self.effects(touched)
        before = self.state()
        for refusal, body in zip(todo, sent, strict=True):
            address = self.address(refusal)
            r = self.send(body, address=address)
            code_rule = refusal.rule or range_rule(body, self.ctx.profile)
            holds(r is not None and r.code in (refusal.code, *refusal.also), code_rule,
                  f"!{address}{body} answered {r}, expected code {refusal.code}")
            self.repeated(body, r.raw, address)
            if address != self.link.address:
                got = self.index()
                holds(got == self.model.index, "6.checksum.spindle-shares",
                      f"index {got} after !{address}{body}, model {self.model.index}: "
                      "address 7 does not count in the index of address 0")
            before = self.unchanged(before, f"!{address}{body} refused with {refusal.code}",
                                    "4.response.failed-not-executed")
        self.effects_unchanged(reference, ", ".join(
            b for r, b in zip(todo, sent, strict=True)
            if r.address == UNIT and effect_of(b)) + " refused",
            "4.response.failed-not-executed")

    @precondition(lambda self: "*S" in self.ctx.profile.commands)
    @rule(first=st.integers(0, len(FAILED_PACKETS) - 1))
    def failed_packet(self, first: int) -> None:
        """Every failing packet, one after the other from a drawn one on: each leaves
        the state read back as it was, and what its B and V members would have set reads
        as before, read once after them all."""
        packets = FAILED_PACKETS[first:] + FAILED_PACKETS[:first]
        touched = {effect_of(m) for p in packets for m in p[0]} - {None}
        self.trips = []
        reference = self.effects(touched)
        before = self.state()
        for members, n, want in packets:
            self.send("*S", answer=False)
            self.model.open_packet()
            for m in members:
                self.send(m, answer=False)
            r = self.send(f"*E{n}")
            holds(r is not None and r.code == want, "7.packet.codes",
                  f"{', '.join(members)}, *E{n} answered {r}, expected code {want}")
            self.repeated(f"*E{n}", r.raw)
            before = self.unchanged(before, f"the packet {', '.join(members)}, *E{n}",
                                    "7.packet.all-or-nothing")
        self.effects_unchanged(reference, "the packets " + "; ".join(
            f"{', '.join(m)}, *E{n}" for m, n, _ in packets), "7.packet.all-or-nothing")

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
        """An example that ends with the queue halted resumes it: where G takes it is the
        last read-back of what the refusals left in it. After a failure (an exception on
        its way out) the queue is only deleted, so that the failure is the one reported."""
        if not self.halted:
            return
        if sys.exc_info()[1] is None:
            self.resume()
        else:
            self.send("D")


@case("4.machine.refusals-read-back",
      rules=("4.response.failed-not-executed", "7.packet.all-or-nothing", "7.packet.codes",
             "8.repeat.remembered", "8.repeat.answer", "8.index.counts", "5.code.unknown",
             "5.code.syntax", "5.code.range", "5.code.nothing-to-go", "5.code.queue-full",
             "5.code.busy-run", "3.frame.watchdog-time", "10.3.status.all-bits", "10.cmd.set-axis",
             "10.1.queue.line-alone", "10.cmd.output", "10.1.queue.cont-buffer",
             "10.4.halt.ramp", "10.4.delete", "10.cmd.modal", "10.4.go.resume",
             "10.cmd.accel-range", "10.cmd.axis-limits", "1.profile.v-b-range-gve54",
             "1.profile.v-b-range", "12.spindle.speed", "6.checksum.spindle-shares",
             "10.1.queue.wait-idiom", "10.3.st6.bits"))
def readback_machine(ctx: CaseContext) -> None:
    """After every refused frame and every failed packet the state read back at rest is
    as before (V, A, VL and XM by a move's effect, B by a junction's, T by a dwell's, the
    micro-step mode by a step's, the spindle where a rig reads it, the queue by where G
    ends it); > shows the refused frame and its answer."""
    run_machine(ctx, ReadBackMachine)
