"""Spec section 10, Commands: the cases that check it.

Every command of the instruction set with its parameters, ranges and answer.

The position counters over their whole range. `N<axis> n` sets a counter without any motion,
so the ends of ±2147483647 are reached on any unit whatever its envelope; a short move that
ends on an end shows the counters count there too.

The reference run, on the test rig's switches and inputs. Never sent to a real unit without
--allow-destructive (the axis travels to its switch)."""

from __future__ import annotations

import re
from collections.abc import Collection

from conformance.case.context import CaseContext, case
from conformance.cases._kit import (
    answers,
    code,
    code_text,
    configured,
    finished,
    halted_with_queue,
    measured_case,
    position,
    setup,
    show,
    step_factor,
    vector,
)
from conformance.link.framing import Response
from conformance.motion.probe import Probe
from conformance.protocol.catalogue import classes
from conformance.protocol.wire import HEX_BYTE
from gve_fixtures.protocol import SECOND, ErrorCode

#: steps of the moves that end on a counter's end (well inside the directed envelope)
RUN_IN = 100


def _set(ctx: CaseContext, axis: str, value: int, want: ErrorCode, rule: str) -> None:
    code(ctx, ctx.link.send(f"N{axis}{value}"), want, f"N{axis}{value} → {want}", rule=rule)


def _reads(ctx: CaseContext, expected: list[int], what: str) -> None:
    got = position(ctx)
    ctx.expect(got == expected, what, observed=got, expected=expected, rule="10.cmd.positions")


def _settle(ctx: CaseContext) -> None:
    r = finished(ctx, 30, lambda r: r.code != ErrorCode.QUEUE_FULL)
    ctx.require(r is not None and r.ok, "the moves did not end within 30 s")


#: per-axis limits, each its own: a limit taken from another axis changes every move
LIMITS = (600, 1200, 1800, 2400)


#: a move along each axis alone, there and back (commanded steps), then where it ends;
#: on the GVE114 A leads X, which shows A's limit in X's counter
AXIS_MOVES = ((600, 0, 0), (0, 600, 0), (0, 0, 600))


A_MOVE = (100, 0, 0, 600)


#: an answer of one byte: `0,` and two hex digits
HEX_ANSWER = rf"0,{HEX_BYTE}"


# command -> (a valid frame on an idle unit after reset, a regex of its answer, the rule
# of spec 10 it checks)
FORMATS = {
    "?": ("?", r"0,.+", "1.profile.version"), "Q": ("Q", r"0,\d{8}", "10.cmd.processor"),
    "T": ("T10", "0", "10.cmd.modal"), "$": ("$100", "0", "10.cmd.modal"),
    "A": ("A100", "0", "10.cmd.accel-range"), "V": ("V1000", "0", "10.cmd.modal"),
    "B": ("B1000", "0", "10.cmd.modal"), "VL": ("VL1000,1000,1000", "0", "10.cmd.axis-limits"),
    "VK": ("VK", "0", "10.cmd.vk-vn"), "VN": ("VN", "0", "10.cmd.vk-vn"),
    "XA": ("XA", "0", "10.cmd.exchange-velocity"), "XU": ("XU", "0", "10.cmd.exchange-velocity"),
    "XD": ("XD", "0", "10.cmd.exchange-velocity"), "XM": ("XM100", "0", "10.cmd.override"),
    "P": ("P", r"0,-?\d+,-?\d+", "10.cmd.positions"),
    "PF": ("PF", r"0(,-?\d+){3}", "10.cmd.positions"), "N": ("N", "0", "10.cmd.zero"),
    "NX": ("NX0", "0", "10.cmd.set-axis"), "NY": ("NY0", "0", "10.cmd.set-axis"),
    "NZ": ("NZ0", "0", "10.cmd.set-axis"), "NA": ("NA0", "0", "10.cmd.set-axis-a"),
    "ER": ("ER05", HEX_ANSWER, "10.cmd.eeprom-bytes"),
    "EFR": ("EFR30", r"0,\S+", "10.cmd.eeprom-words"),
    "EUR": ("EUR4C", r"0,\d+", "10.cmd.eeprom-words"), "O0": ("O0,FF", "0", "10.cmd.output"),
    "I0": ("I0", HEX_ANSWER, "10.cmd.inputs"),
    "I1": ("I1", HEX_ANSWER, "10.cmd.inputs"),
    "I2": ("I2", HEX_ANSWER, "10.cmd.inputs"),
    "SR": ("SR0", HEX_ANSWER, "10.cmd.status-words"),
    "SW": ("SW0,00", "0", "10.cmd.status-words"), "F": ("F", HEX_ANSWER, "10.cmd.flags"),
    "@": ("@", r"0,(0|[1-9]\d*)", "8.index.decimal"), "H": ("H", "8", "10.cmd.halt-answer"),
}


# commands of spec 10 a profile may lack (the refusal is 3)
OPTIONAL = classes(optional=True)


#: N<axis> and I<port>: the letter after the command is a parameter (spec 5, code 3)
LACKING_LETTER = re.compile(r"N[A-Z]\Z|I[0-9]\Z")


REFUSAL_FRAMES = {"VL": "VL1000,1000,1000", "VK": "VK", "VN": "VN", "XM": "XM100",
                  "NX": "NX0", "NY": "NY0", "NZ": "NZ0", "NA": "NA0", "W": "WX,100,100,100,100",
                  "EFR": "EFR30", "EFW": "EFW30,1", "EUR": "EUR30", "EUW": "EUW30,1",
                  "M": "M4", "Y": "Y-", "I0": "I0", "I2": "I2", "%": "%+", "*S": "*S",
                  "*E": "*E1"}


# id -> (rules (the first judges the readings), commands it requires, families, scenario)
SCENARIOS: dict[str, tuple[tuple[str, ...], tuple[str, ...], tuple[str, ...], list]] = {
    # XM acts at once on the running and the queued vectors (10)
    "10.cmd.measured.override": (
        ("10.cmd.override",), ("XM",), (),
        ["V1000", "C700,0,0", "C700,0,0", 0.2, "XM200", 0.45, "XM50", 0.2]),
    # XA: the running and queued vectors take the modal V (10)
    "10.cmd.measured.exchange-xa": (
        ("10.cmd.exchange-velocity", "10.1.queue.captured"), (), (),
        ["V1000", "C600,0,0", "C600,0,0", 0.2, "V3000", 0.1, "XA", 0.35]),
    # XU / XD: ×17/16, ×15/16 (10)
    "10.cmd.measured.exchange-xu-xd": (
        ("10.cmd.exchange-velocity",), (), (),
        ["A10000", "V1600", "C1200,0,0", 0.15, "XU", 0.15, "XD", 0.15, "XD", 0.15]),
    # GVE54: XA/XU/XD also set or scale the acceleration (10)
    "10.cmd.measured.exchange-accel": (
        ("10.cmd.exchange-accel-gve54",), (), ("GVE54",),
        ["A2", "V3000", "C1500,0,0", 0.1, "A10", "XA", 0.2, "XD", 0.2]),
}


for _id, (_rules, _requires, _families, _scenario) in SCENARIOS.items():
    measured_case(_id, _rules, _requires, _families, _scenario)


@case("10.cmd.flags-after-keep.one-vector", applies=lambda p: p.keep == "single-L",
      rules=("10.cmd.flags-after-keep",))
def flags_after_keep(ctx: CaseContext) -> None:
    setup(ctx, "K")
    setup(ctx, "L" + vector(ctx, 300))
    answers(ctx, ctx.link.send("F"), "0,60", "F after K and one L: RUN and queue full")


@case("10.cmd.measured.axis-limits-own-axis", timing=True, requires=("VL",),
      rules=("10.cmd.axis-limits-own-axis", "10.cmd.axis-limits", "10.2.motion.axis-caps"))
def axis_limits(ctx: CaseContext) -> None:
    configured(ctx, "a-axis-alone")          # the GVE114's A moves alone, not with X, Y, Z
    axes = len(ctx.profile.axes)
    moves = [*AXIS_MOVES, *((A_MOVE,) if axes == 4 else ())]
    steps: list = ["A10000", "V3000", "VL" + ",".join(map(str, LIMITS[:axes]))]
    at = [0, 0, 0]
    for m in moves:
        for sign in (1, -1):
            steps.append("L" + ",".join(str(sign * x) for x in m))
            at = [a + sign * x for a, x in zip(at, m[:3], strict=True)]
            steps.append(list(at))
            if len(m) == 4:          # X stands at its end a few of A's steps before A does
                steps.append((0.1, 0.02))
    Probe(ctx, "each axis alone under VL" + ",".join(map(str, LIMITS[:axes])),
          "10.cmd.axis-limits-own-axis").script(steps)


@case("10.cmd.measured.override-leaves-v", timing=True, requires=("XM",),
      rules=("10.cmd.override-leaves-v", "10.cmd.override"))
def override_leaves_v(ctx: CaseContext) -> None:
    Probe(ctx, "XM200 over V1000, then XM100", "10.cmd.override-leaves-v").script(
        ["A10000", "V1000", "XM200", "L600,0,0", [600, 0, 0], "XM100", "L-600,0,0",
         [0, 0, 0]])


@case("10.cmd.mpg.modes", requires=("Y",), rules=("10.cmd.mpg", "9.reset.mpg-parameters"))
def mpg_modes(ctx: CaseContext) -> None:
    """Y answers the command back with the hand wheel usable: enabled, every parameter the
    manual names for it in range (M114 12: otherwise "the MPG cannot be used"). Where one
    is out of range and writing it is not allowed, whether Y+ and Y& may turn the MPG on is
    a reading."""
    on = "10.cmd.mpg" if configured(ctx, "mpg", required=False) else "9.reset.mpg-parameters"
    for c in ("+", "&", "-"):
        answers(ctx, ctx.link.send(f"Y{c}"), f"0,Y{c}", f"Y{c} answers the command back",
                rule=on if c != "-" else "10.cmd.mpg")


@case("10.cmd.mpg.while-moving", requires=("Y",), rules=("10.cmd.mpg-while-moving",))
def mpg_while_moving(ctx: CaseContext) -> None:
    """`Y&` (the reset's mode) sent while an L runs, the MPG not enabled (M114 12.2): taken
    (spec 10 [D]; a unit may refuse it with 7 while the axes move)."""
    configured(ctx, "mpg-off")
    setup(ctx, "L" + vector(ctx, 300))
    answers(ctx, ctx.link.send("Y&"), "0,Y&", "Y& while an L runs → 0,Y&",
            rule="10.cmd.mpg-while-moving")


@case("10.cmd.output.port", rig=True, rules=("10.cmd.output",))
def output(ctx: CaseContext) -> None:
    configured(ctx, "outputs-by-host")
    link = ctx.link
    answers(ctx, link.send("O0,FB"), "0", "O0,FB: coolant on")
    seen = link.rig.outputs()                # read once: a technician may be the one asked
    ctx.expect(seen == 0xFB, "the outputs are FB", observed=seen, expected=0xFB)
    answers(ctx, link.send("O1,FF"), "5", "O1,FF: port 1 does not exist")
    answers(ctx, link.send("O"), "4", "O without parameters")
    seen = link.rig.outputs()
    ctx.expect(seen == 0xFB, "the refused frames changed nothing", observed=seen,
               expected=0xFB)
    answers(ctx, link.send("O0,FF"), "0", "O0,FF: all off")


@case("10.cmd.output.while-busy", rig=True, rules=("10.cmd.output",))
def output_while_busy(ctx: CaseContext) -> None:
    """O sets the outputs when it is answered, whatever the motion: while a vector runs
    and while halted vectors are held (nothing in the manuals defers it)."""
    configured(ctx, "outputs-by-host")
    link = ctx.link
    halted_with_queue(ctx, vectors=2, steps=200)
    code(ctx, link.send("O0,FB"), ErrorCode.OK, "O0,FB while halted vectors are held")
    seen = link.rig.outputs()
    ctx.expect(seen == 0xFB, "the outputs are FB while halted vectors are held",
               observed=seen, expected=0xFB)
    setup(ctx, "G")
    answers(ctx, link.send("O0,F7"), "0", "O0,F7 while the vectors run")
    seen = link.rig.outputs()
    ctx.expect(seen == 0xF7, "the outputs are F7 while the vectors run", observed=seen,
               expected=0xF7)
    finished(ctx, 30, lambda r: r.code != ErrorCode.QUEUE_FULL)
    answers(ctx, link.send("O0,FF"), "0", "O0,FF: all off")


@case("10.cmd.ports.bit-by-bit", rig=True,
      rules=("10.cmd.port-bits", "10.cmd.inputs", "10.cmd.output"))
def ports(ctx: CaseContext) -> None:
    configured(ctx, "outputs-by-host")
    link, rule = ctx.link, "10.cmd.port-bits"
    answers(ctx, link.send("SW0,00"), "0", "interrupts off", rule="10.cmd.inputs")
    answers(ctx, link.send("SW1,00"), "0", "interrupts off", rule="10.cmd.inputs")
    for port in ctx.profile.input_ports:
        # a bit its manual calls unused has no pin to ground; what it reads is silent
        unused = ctx.profile.unused_inputs.get(port, 0)
        pins = [bit for bit in range(8) if not unused & 1 << bit]
        for level in [0xFF ^ (1 << bit) for bit in pins] + [0x00, 0xFF]:
            link.rig.set_input(port, level)
            r = link.send(f"I{port}")
            shown = f"I{port} with {'no pin' if level == 0xFF else 'pins'} grounded: " \
                    f"{level:08b}"
            if not unused:
                answers(ctx, r, "0,%02X" % level, shown, rule=rule)
                continue
            seen = r.hex() if r is not None and r.ok and r.values[:1] else None
            ctx.expect(seen is not None and seen & ~unused & 0xFF == level & ~unused & 0xFF,
                       shown + f" (bits {unused:08b} unused)", observed=show(r),
                       expected="0,%02X in the bits with pins" % (level & ~unused & 0xFF),
                       rule=rule)
    for level in [0xFF ^ (1 << bit) for bit in range(8)] + [0x00, 0xFF]:
        answers(ctx, link.send("O0,%02X" % level), "0", "O0,%02X" % level, rule="10.cmd.output")
        seen = link.rig.outputs()
        ctx.expect(seen == level, f"the outputs read {level:08b}", observed=f"{seen:08b}",
                   expected=f"{level:08b}", rule=rule)
    code(ctx, link.send("O0,100"), ErrorCode.RANGE,
         "O0,100: one beyond FF → 5", rule="10.cmd.output")
    seen = link.rig.outputs()
    ctx.expect(seen == 0xFF, "the refused O0,100 left the outputs off", observed=seen,
               expected=0xFF, rule="10.cmd.output")


def _answered_after_the_run(ctx: CaseContext, r, body: str, steps: int, rate: int) -> None:
    """W answers when its run has ended (the manual's rule), judged by every means the
    unit itself gives: not before the ``steps`` it ran at ``rate`` could have taken, RUN
    clear right after its answer, its counters standing still from its answer on."""
    rule = "10.cmd.reference"
    ctx.require(r is not None, f"{body} got no answer")
    took = (r.received_at - r.sent_at) / SECOND
    ctx.expect(took >= steps / rate, f"{body} answers once its {steps} steps at {rate}/s "
               "are done", observed=f"{took:.3f} s", expected=f"at least {steps / rate:.3f} s",
               rule=rule)
    run = ctx.link.send("SR6")
    ctx.expect(run is not None and run.ok and run.values[:1] and not run.hex() & 0x40,
               f"{body}: RUN clear right after its answer", observed=show(run),
               expected="RUN (bit 6) clear", rule=rule)
    here = position(ctx)
    ctx.link.wait(0.2)
    ctx.expect_equal(position(ctx), here, f"{body}: the counters stand still from its answer on",
                     rule=rule)


def _reference(ctx: CaseContext, axis: str, *numbers: int) -> tuple[str, Response | None]:
    """W on ``axis`` in the form of its format line and M84's example (a comma after the
    axis); refused as a syntax error (nothing ran), in the form of M114's example
    (`!0WY-20000,1000,2000,500`): a reader may take either, the form refused is judged by
    its [D] rule and the run by the form taken. Returns (the frame taken, its answer)."""
    rest = ",".join(str(n) for n in numbers)
    body = f"W{axis},{rest}"
    r = ctx.link.send(body)
    if r is None or r.code != ErrorCode.SYNTAX:
        return body, r
    ctx.expect(False, f"{body} (a comma after the axis) is accepted", observed=show(r),
               expected="not 4", rule="10.cmd.reference-syntax")
    body = f"W{axis}{rest}"
    return body, ctx.link.send(body)


@case("10.cmd.reference.answers-after-travel", destructive=True, requires=("W",),
      rules=("10.cmd.reference", "10.cmd.reference-fails", "10.cmd.reference-syntax"))
def answers_after_travel(ctx: CaseContext) -> None:
    """W on each axis with a short travel and no switch expected within it: the answer
    comes after the run, by the unit's own time, flags and counters (no rig needed); not
    found, it is 5 with the axis where the travel ended."""
    for i, axis in enumerate(ctx.profile.axes[:3]):
        start = position(ctx)
        ctx.require(start is not None, "PF did not answer with positions")
        body, r = _reference(ctx, axis, -100, 1000, 50, 1000)
        ran = 100 if r is not None and r.code == ErrorCode.RANGE else 0
        _answered_after_the_run(ctx, r, body, ran, 1000)
        if r is not None and r.code == ErrorCode.RANGE:
            want = [s - 100 * (j == i) for j, s in enumerate(start)]
            ctx.expect_equal(position(ctx), want,
                             f"{body}: not found, the axis where the travel ended",
                             rule="10.cmd.reference-fails")
            setup(ctx, "L" + vector(ctx, *[100 * (j == i) for j in range(3)]))
            _settle(ctx)


def _ran(r: Response | None, steps: int) -> int:
    """The steps a W the rig's inputs judge has run by its answer, under every reading of
    which input is the axis's switch (10.cmd.reference-switch [D]): 5, its whole travel
    (``steps``); another answer, a switch found and released: at least the one step that
    released it."""
    return steps if r is not None and r.code == ErrorCode.RANGE else 1


@case("10.cmd.reference.inputs", rig=True, destructive=True, requires=("W",),
      rules=("10.cmd.reference-switch", "10.cmd.reference-fails", "10.cmd.reference",
             "10.cmd.reference-syntax"))
def inputs(ctx: CaseContext) -> None:
    link = ctx.link
    link.rig.set_input(1, 0xFD)              # IN1 grounded: Y's switch, active at polarity 0
    body, r = _reference(ctx, "X", -100, 1000, 50, 1000)
    answers(ctx, r, "5", "X watches IN0, which is not active: not found within 100 steps",
            rule="10.cmd.reference-fails")
    _answered_after_the_run(ctx, r, body, _ran(r, 100), 1000)
    ctx.expect_equal(position(ctx), [-100, 0, 0], "X stayed where the travel ended",
                     rule="10.cmd.reference-fails")
    body, r = _reference(ctx, "Y", -100, 1000, 50, 1000)
    answers(ctx, r, "5", "Y watches IN1, active all the way back: still active after 50 "
            "steps back", rule="10.cmd.reference-switch")
    _answered_after_the_run(ctx, r, body, _ran(r, 50), 1000)
    ctx.expect_equal(position(ctx), [-100, 50, 0],
                     "Y stayed 50 steps back from where it found it",
                     rule="10.cmd.reference-fails")
    link = ctx.fresh_link()
    link.rig.set_input(1, 0xFF)
    setup(ctx, "SW2,04")                     # Z's input IN2 active at log. 1: it is
    body, r = _reference(ctx, "Z", -100, 1000, 30, 1000)
    answers(ctx, r, "5", "Z watches IN2 under the polarity rule (active at 1, reads 1)",
            rule="10.cmd.reference-switch")
    _answered_after_the_run(ctx, r, body, _ran(r, 30), 1000)
    ctx.expect_equal(position(ctx), [0, 0, 30], "Z found it at once and backed off 30 steps",
                     rule="10.cmd.reference-switch")


@case("10.cmd.reference.to-switch", rig=True, destructive=True, requires=("W",),
      rules=("10.cmd.reference", "10.cmd.reference-syntax", "2.link.answer-promptly"))
def to_switch(ctx: CaseContext) -> None:
    link = ctx.link
    link.rig.set_switch("X", -150)
    body, r = _reference(ctx, "X", -1000, 2000, 200, 1000)
    answers(ctx, r, "0", f"{body} finds the switch", rule="10.cmd.reference")
    took = None if r is None else (r.received_at - r.sent_at) / SECOND
    ctx.expect(took is not None and took >= 150 / 2000, "W answers once the axis has stopped",
               observed=f"{took} s", expected="at least the 75 ms to the switch",
               rule="2.link.answer-promptly")
    _answered_after_the_run(ctx, r, body, 150, 2000)
    ctx.expect_equal(position(ctx), [0, 0, 0], "the counter is 0 where the switch releases",
                     rule="10.cmd.reference")
    link.rig.set_switch("X", None)
    link.rig.set_switch("Y", -100)
    answers(ctx, link.send("WY-1000,2000,200,1000"), "0",
            "WY-1000,... (no comma after the axis) is accepted too",
            rule="10.cmd.reference-syntax")
    ctx.expect_equal(position(ctx), [0, 0, 0], "Y's counter is 0 where its switch releases",
                     rule="10.cmd.reference")


def _begins_one_it_has(name: str, commands: Collection[str]) -> bool:
    """Whether letters before the end of ``name`` begin a command of ``commands`` (`V`
    of `VL`, `N` of `NX`, `X` of `XA` for `XM`): a unit may take the rest for parameters
    of that command (1.profile.command-prefix [D])."""
    return any(c.startswith(name[:i]) for i in range(1, len(name)) for c in commands)


@case("10.commands.absent-refused",
      rules=("1.profile.command-set", "5.code.unknown", "1.profile.command-prefix"))
def absent(ctx: CaseContext) -> None:
    """A command the profile lacks answers 3."""
    lacking = [c for c in REFUSAL_FRAMES if c in OPTIONAL and c not in ctx.profile.commands]
    if not lacking:
        ctx.expect(True, "the profile has every optional command", rule="1.profile.command-set")
    for name in lacking:
        r = ctx.link.send(REFUSAL_FRAMES[name])
        # an axis or port the unit lacks may be a parameter out of range instead (spec 5)
        if LACKING_LETTER.match(name) and r is not None and r.code == ErrorCode.RANGE:
            ctx.expect(True, f"{name} → 5: the letter a parameter the unit lacks",
                       rule="5.code.unknown")
            continue
        # where its manual never says where a command's name ends, the letters after
        # one it has may be that command's parameters, which it does not take: 4
        if r is not None and r.code == ErrorCode.SYNTAX \
                and _begins_one_it_has(name, ctx.profile.commands):
            ctx.expect(False, f"{name} → 3: one command the unit lacks, not a command it "
                       "has with parameters it does not take", observed=show(r),
                       expected=code_text(ErrorCode.UNKNOWN), rule="1.profile.command-prefix")
            continue
        code(ctx, r, ErrorCode.UNKNOWN, f"{name} → 3", rule="1.profile.command-set")


@case("10.commands.counter-range-ends", requires=("NX",),
      rules=("10.cmd.set-axis", "10.cmd.positions", "5.code.range", "10.cmd.set-axis-a"))
def range_ends(ctx: CaseContext) -> None:
    p = ctx.profile
    lo, hi = p.ranges["position"].lo, p.ranges["position"].hi
    shown = p.axes[:3]                       # PF reads X Y Z (the GVE114's A is not shown)
    scale = step_factor(ctx)
    start = position(ctx)
    ctx.require(start is not None, "PF did not answer with positions")
    # first the moves, each ending on an end and coming back: read while the vector may
    # still run as far as the guard knows (PF until it shows the end), so that a unit
    # whose counters wrap is not taken for one whose axes went elsewhere, and the axes
    # come back whatever it reads
    near = [hi - RUN_IN, lo + RUN_IN, hi - RUN_IN]
    for axis, value in zip(shown, near, strict=True):
        _set(ctx, axis, value, ErrorCode.OK, "10.cmd.set-axis")
    for d, there, what in (((RUN_IN, -RUN_IN, RUN_IN), [hi, lo, hi], "a move counted up to "
                            "the ends"), ((-RUN_IN, RUN_IN, -RUN_IN), near, "and back")):
        setup(ctx, "L" + vector(ctx, *d))
        want = [v * scale for v in there]
        r = ctx.link.poll("PF", lambda r, want=want: r.ok and r.values == [
            str(v) for v in want], 5.0, every=0.02)
        got = r.decs() if r is not None else position(ctx)
        ctx.expect(r is not None, what, observed=got, expected=want, rule="10.cmd.positions")
    _settle(ctx)
    # then each axis at each end, its neighbours at the other: every reading tells them apart
    for ends in ((hi, lo, hi), (lo, hi, lo)):
        for axis, value in zip(shown, ends, strict=True):
            _set(ctx, axis, value, ErrorCode.OK, "10.cmd.set-axis")
        _reads(ctx, [v * scale for v in ends], f"PF reads the counters at {ends}")
        for axis, value in zip(shown, ends, strict=True):
            beyond = value + (1 if value > 0 else -1)
            _set(ctx, axis, beyond, ErrorCode.RANGE, "5.code.range")
        _reads(ctx, [v * scale for v in ends], "the refused N<axis> changed no counter")
    if "NA" in p.commands:                   # the A counter: set and refused, not read
        # M114 names the axes of N<axis> X, Y, Z: NA and its range are the project's
        for value, want in ((hi, ErrorCode.OK), (hi + 1, ErrorCode.RANGE), (lo, ErrorCode.OK),
                            (lo - 1, ErrorCode.RANGE), (0, ErrorCode.OK)):
            _set(ctx, "A", value, want, "10.cmd.set-axis-a")
    # back where the case began
    for axis, value in zip(shown, start, strict=True):
        _set(ctx, axis, value // scale, ErrorCode.OK, "10.cmd.set-axis")
    _reads(ctx, start, "the counters are back where the case found them")


@case("10.commands.formats",
      rules=("4.response.grammar", *sorted({rule for _, _, rule in FORMATS.values()})))
def formats(ctx: CaseContext) -> None:
    """Every command of the profile answers in the format of spec 10."""
    for name, (body, pattern, rule) in FORMATS.items():
        if name not in ctx.profile.commands:
            continue
        link = ctx.fresh_link()
        r = link.send(body)
        ctx.expect(r is not None and r.well_formed, f"{body}: a well-formed response",
                   observed=show(r), expected="code *(,value) CR", rule="4.response.grammar")
        ok = r is not None and re.fullmatch(pattern, r.raw.decode("latin-1").rstrip("\r"))
        ctx.expect(bool(ok), f"{body}", observed=show(r), expected=pattern, rule=rule)


@case("10.commands.zero-axis",
      rules=("10.cmd.set-axis", "10.cmd.zero"),
      requires=("NX",))
def set_axis(ctx: CaseContext) -> None:
    """!0NX100 sets the X counter; !0N zeroes every axis."""
    answers(ctx, ctx.link.send("NX100"), "0", "NX100", rule="10.cmd.set-axis")
    ctx.expect_equal(position(ctx), [100, 0, 0], "X = 100", rule="10.cmd.set-axis")
    answers(ctx, ctx.link.send("N"), "0", "N", rule="10.cmd.zero")
    ctx.expect_equal(position(ctx), [0, 0, 0], "all zero", rule="10.cmd.zero")


#: each axis's own count in the read-back moves (commanded steps): different sizes and
#: signs, so that a count read on the wrong axis, or one axis's move taken for another's,
#: shows
AXIS_COUNTS = (37, -53, 71, -89)


def _subsets(n: int) -> list[tuple[int, ...]]:
    """Every non-empty set of axes, each alone first, then by size: (0,), (1,), ..."""
    return sorted((tuple(i for i in range(n) if m >> i & 1) for m in range(1, 1 << n)),
                  key=lambda s: (len(s), s))


#: the rate of the read-back moves: slow enough that the shortest (37 steps) still runs
#: for 185 ms, so that `SR6` right after it shows it running on any line
AXIS_RATE = 200


def _move(ctx: CaseContext, kind: str, axes: tuple[int, ...], sign: int) -> list[int]:
    """A vector moving ``axes`` by their own counts; right after it, while it must still
    run (its dominant count at the rate, less what the exchanges took), RUN shows it
    being processed: an axis the unit took as not moving ends it at once."""
    counts = [sign * AXIS_COUNTS[i] if i in axes else 0 for i in range(len(ctx.profile.axes))]
    body = kind + ",".join(map(str, counts))
    r = setup(ctx, body)
    run = ctx.link.send("SR6")
    lasts = max(map(abs, counts)) * SECOND // AXIS_RATE
    if r is not None and run is not None and run.received_at - r.sent_at < lasts:
        ctx.expect(run.ok and run.values[:1] and run.hex() & 0x40,
                   f"{body}: right after it the vector runs (RUN)", observed=show(run),
                   expected="RUN (bit 6) set", rule="10.cmd.vector")
    _settle(ctx)
    return counts


@case("10.cmd.positions.each-axis", timing=True,
      rules=("10.cmd.positions", "10.cmd.vector"))
def each_axis(ctx: CaseContext) -> None:
    """Every axis the protocol reads (PF: X, Y, Z; P: X, Y) after moving alone, in each
    pair and all together, with L and with C: each counter moved by its own count and no
    other moved. The GVE114's A is moved too (it leads no counter PF shows)."""
    scale = step_factor(ctx)
    start = position(ctx)
    ctx.require(start is not None, "PF did not answer with positions")
    setup(ctx, f"V{AXIS_RATE}")
    for kind in ("L", "C"):
        for axes in _subsets(len(ctx.profile.axes)):
            counts = _move(ctx, kind, axes, 1)
            want = [s + scale * c for s, c in zip(start, counts, strict=False)]
            names = "".join(ctx.profile.axes[i] for i in axes)
            ctx.expect_equal(position(ctx), want, f"{kind} moving {names}: PF",
                             rule="10.cmd.positions")
            r = ctx.link.send("P")
            ctx.expect(r is not None and r.ok and r.values == [str(v) for v in want[:2]],
                       f"{kind} moving {names}: P", observed=show(r),
                       expected="0,%d,%d" % tuple(want[:2]), rule="10.cmd.positions")
            _move(ctx, kind, axes, -1)
            ctx.expect_equal(position(ctx), start, f"{kind} moving {names} back",
                             rule="10.cmd.vector")


def _rig_axes(ctx: CaseContext, key: str) -> list[int]:
    """The rig's reading of every axis (``position``: the counters; ``physical``)."""
    got = ctx.link.rig.state().get(key)
    ctx.require(isinstance(got, list) and len(got) == len(ctx.profile.axes)
                and all(isinstance(v, int) for v in got),
                f"the rig's state gives no {key!r} for {len(ctx.profile.axes)} axes: {got!r}")
    return got


@case("10.cmd.vector.every-axis-on-the-rig", rig=True, timing=True,
      rules=("10.cmd.vector", "10.cmd.positions"))
def every_axis_on_the_rig(ctx: CaseContext) -> None:
    """Every axis, A included (no command reads it), read where the rig reads it after
    moving alone, in every set of axes and all together: its counter and where it
    physically stands moved by its own count, no other axis moved."""
    scale = step_factor(ctx)
    counters, physical = _rig_axes(ctx, "position"), _rig_axes(ctx, "physical")
    setup(ctx, f"V{AXIS_RATE}")
    for kind in ("L", "C"):
        for axes in _subsets(len(ctx.profile.axes)):
            counts = _move(ctx, kind, axes, 1)
            names = "".join(ctx.profile.axes[i] for i in axes)
            for key, was in (("position", counters), ("physical", physical)):
                want = [w + scale * c for w, c in zip(was, counts, strict=True)]
                got = _rig_axes(ctx, key)
                ctx.expect(got == want, f"{kind} moving {names}: every axis's {key} on the rig",
                           observed=got, expected=want, rule="10.cmd.vector")
            here = position(ctx)
            ctx.expect(here == _rig_axes(ctx, "position")[:3],
                       f"{kind} moving {names}: PF reads the rig's X, Y, Z counters",
                       observed=here, expected=_rig_axes(ctx, "position")[:3],
                       rule="10.cmd.positions")
            _move(ctx, kind, axes, -1)
