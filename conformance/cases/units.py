"""Sections 1, 9, 10 (formats of every command per profile), 10.6 EEPROM, 10.7 GVE54
motor mode, 12 GVE114 spindle."""

from __future__ import annotations

import re

from conformance.case import CaseContext, case
from conformance.cases._kit import (
    answers,
    code,
    fresh_reset,
    index,
    index_moved,
    position,
    setup,
    show,
    vector,
)
from conformance.motion.probe import Probe
from conformance.protocol.catalogue import classes
from conformance.protocol.wire import HEX_BYTE

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
    "NZ": ("NZ0", "0", "10.cmd.set-axis"), "NA": ("NA0", "0", "10.cmd.set-axis"),
    "ER": ("ER05", HEX_ANSWER, "10.cmd.eeprom-bytes"),
    "EFR": ("EFR30", r"0,\S+", "10.cmd.eeprom-words"),
    "EUR": ("EUR4C", r"0,\d+", "10.cmd.eeprom-words"), "O0": ("O0,FF", "0", "10.cmd.output"),
    "I0": ("I0", HEX_ANSWER, "10.cmd.inputs"),
    "I1": ("I1", HEX_ANSWER, "10.cmd.inputs"),
    "I2": ("I2", HEX_ANSWER, "10.cmd.inputs"),
    "SR": ("SR0", HEX_ANSWER, "10.cmd.status-words"),
    "SW": ("SW0,00", "0", "10.cmd.status-words"), "F": ("F", HEX_ANSWER, "10.cmd.flags"),
    "@": ("@", r"0,\d+", "8.index.answer"), "H": ("H", "8", "10.cmd.halt-answer"),
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


@case("10.commands.formats", tag="M", source="M84 12.5; M114 13.6; M54; spec 10",
      rules=("4.response.grammar", *sorted({rule for _, _, rule in FORMATS.values()})),
      rule="Every command of the profile answers in the format of spec 10")
def formats(ctx: CaseContext) -> None:
    for name, (body, pattern, rule) in FORMATS.items():
        if name not in ctx.profile.commands:
            continue
        link = ctx.fresh_link()
        r = link.send(body)
        ctx.expect(r is not None and r.well_formed, f"{body}: a well-formed response",
                   observed=show(r), expected="code *(,value) CR", rule="4.response.grammar")
        ok = r is not None and re.fullmatch(pattern, r.raw.decode("latin-1").rstrip("\r"))
        ctx.expect(bool(ok), f"{body}", observed=show(r), expected=pattern, rule=rule)


@case("10.commands.absent-refused",
      rules=("1.profile.command-set", "5.code.unknown"),
      tag="M", source="spec 1, 5: code 3",
      rule="A command the profile lacks answers 3")
def absent(ctx: CaseContext) -> None:
    lacking = [c for c in REFUSAL_FRAMES if c in OPTIONAL and c not in ctx.profile.commands]
    if not lacking:
        ctx.expect(True, "the profile has every optional command")
    for name in lacking:
        r = ctx.link.send(REFUSAL_FRAMES[name])
        # an axis or port the unit lacks may be a parameter out of range instead (spec 5)
        if LACKING_LETTER.match(name) and r is not None and r.code == 5:
            ctx.expect(True, f"{name} → 5: the letter a parameter the unit lacks")
            continue
        code(ctx, r, 3, f"{name} → 3")


@case("1.profile.version",
      rules=("1.profile.version", "2.link.serial-8n1", "3.frame.grammar"),
      tag="D", source="spec 1 [D]",
      rule="? answers 0,<the profile's firmware string>")
def version(ctx: CaseContext) -> None:
    answers(ctx, ctx.link.send("?"), "0," + ctx.profile.version, "the firmware string",
            rule="1.profile.version")


@case("9.reset.state",
      rules=("9.reset.state", "8.index.counts"),
      tag="M", source="M84 12.4; M114 13.5; M54",
      rule="After reset: ST0..ST6 = 00, position 0, outputs FF, checksums off")
def reset_state(ctx: CaseContext) -> None:
    fresh_reset(ctx)
    before = index(ctx)
    for n in range(7):
        answers(ctx, ctx.link.send(f"SR{n}"), "0,00", f"ST{n} = 00")
    here = position(ctx)
    ctx.expect(here == [0, 0, 0], "position 0", observed=here, expected=[0, 0, 0])
    index_moved(ctx, before, 8, "the index counted the SR and PF frames", rule="8.index.counts")


@case("9.reset.after-j",
      rules=("10.cmd.restart", "9.reset.state", "8.index.answer", "2.link.ready-after-restart"),
      tag="D", source="M84 12.4; spec 9, 10 J [D]", destructive=True,
      rule="J answers a plain 0 and restores the reset state after about 2 s", timing=True)
def after_j(ctx: CaseContext) -> None:
    link = ctx.link
    setup(ctx, "SW2,2B")
    setup(ctx, "L" + vector(ctx, 16))
    link.poll("L" + vector(ctx, 0), lambda r: r.code == 0, 30)
    answers(ctx, link.send("J"), "0", "J → 0", rule="10.cmd.restart")
    link.wait(2.5)
    answers(ctx, link.send("SR2"), "0,00", "ST2 reset", rule="9.reset.state")
    answers(ctx, link.send("@"), "0,1", "the index restarted at 0", rule="8.index.answer")
    ctx.expect(position(ctx) == [0, 0, 0], "position zeroed", rule="9.reset.state")


@case("10.6.eeprom.round-trip",
      rules=("10.cmd.eeprom-bytes",),
      tag="M", source="M84 11; M114 11-12", destructive=True,
      rule="EW writes a byte that ER reads back (kept, then restored by the suite)")
def eeprom(ctx: CaseContext) -> None:
    link = ctx.link
    r = link.send("ER40")
    ctx.require(r is not None and r.code == 0, "ER40 answered")
    old = r.hex()
    new = old ^ 0x5A
    answers(ctx, link.send("EW40,%02X" % new), "0", "EW40 → 0")
    answers(ctx, link.send("ER40"), "0,%02X" % new, "ER40 reads the new byte")


@case("10.6.eeprom.words",
      rules=("10.cmd.eeprom-words", "3.params.word-values-decimal"),
      tag="D", source="spec 10 EFR/EUR [D]", destructive=True,
      requires=("EFW", "EUW"), rule="EFW/EFR store float32 and EUW/EUR uint32 little-endian")
def words(ctx: CaseContext) -> None:
    link = ctx.link
    answers(ctx, link.send("EFW30,0.25"), "0", "EFW30,0.25")
    answers(ctx, link.send("EFR30"), "0,0.25", "EFR30 → 0.25")
    answers(ctx, link.send("ER33"), "0,3E", "the float's top byte at 33 (little-endian)")
    answers(ctx, link.send("EUW40,305419896"), "0", "EUW40")
    answers(ctx, link.send("ER40"), "0,78", "the uint's low byte first")
    code(ctx, link.send("EFRFD"), 5, "a word past FF → 5")


@case("10.7.microstep.positions-in-sixteenths",
      rules=("10.2.motion.gve54-units", "10.7.motor.modes"),
      tag="M-ex", source="M54 (G5)",
      requires=("M",), rule="GVE54 positions are in 1/16 steps: M4, L100,100,100 → 400")
def microstep(ctx: CaseContext) -> None:
    link = ctx.link
    setup(ctx, "M4")
    setup(ctx, "L100,100,100")
    link.poll("L0,0,0", lambda r: r.code == 0, 60)
    answers(ctx, link.send("PF"), "0,400,400,400", "PF after M4 and L100,100,100")
    code(ctx, link.send("MQ"), 4, "an unknown mode → 4", tag="D")


@case("12.spindle.address-7",
      rules=("12.spindle.speed", "12.spindle.commands"),
      tag="M-ex", source="M114 13.7 (G8)", rig=True,
      applies=lambda p: p.spindle is not None,
      rule="!7V<n> sets the spindle (per mille); V0 switches OUT0 off; !0V is the feed rate")
def spindle(ctx: CaseContext) -> None:
    link = ctx.link
    speed = "12.spindle.speed"
    answers(ctx, link.send("V300", address=7), "0", "!7V300", rule=speed)
    ctx.expect(link.rig.spindle() == 300, "spindle 300", observed=link.rig.spindle(),
               rule=speed)
    ctx.expect(link.rig.outputs() & 1 == 0, "OUT0 on", observed=link.rig.outputs(), rule=speed)
    answers(ctx, link.send("V0", address=7), "0", "!7V0", rule=speed)
    ctx.expect(link.rig.outputs() & 1 == 1, "OUT0 off", observed=link.rig.outputs(), rule=speed)
    code(ctx, link.send("L1,0,0", address=7), 3, "address 7 takes no vectors",
         rule="12.spindle.commands")


#: the move each micro-step mode makes (commanded steps): a factor of another mode ends
#: elsewhere on every axis
MODE_MOVE = (60, -30, 15)


def _rest(ctx: CaseContext) -> None:
    r = ctx.link.poll("L0,0,0", lambda r: r.code != 1, 30)
    ctx.require(r is not None and r.code == 0, "the move did not end within 30 s")


@case("10.7.microstep.each-mode", requires=("M",), timing=True,
      rules=("10.7.motor.modes", "10.7.motor.rates-scaled", "10.2.motion.gve54-units"))
def each_mode(ctx: CaseContext) -> None:
    """Every micro-step mode with the same move: where it ends (exact, in sixteenths) and
    how it gets there (measured, the rates scaled by the mode's factor)."""
    ms = ctx.profile.microstep
    start = position(ctx)
    ctx.require(start is not None, "PF did not answer with positions")
    for mode, factor in ms.factors.items():
        setup(ctx, f"M{mode}")
        setup(ctx, "L" + vector(ctx, *MODE_MOVE))
        _rest(ctx)
        want = [s + factor * d for s, d in zip(start, MODE_MOVE, strict=True)]
        ctx.expect(position(ctx) == want, f"M{mode}: L{vector(ctx, *MODE_MOVE)} ends "
                   f"{factor} sixteenths a step on", observed=position(ctx), expected=want,
                   rule="10.7.motor.modes")
        setup(ctx, "L" + vector(ctx, *(-d for d in MODE_MOVE)))
        _rest(ctx)
    setup(ctx, f"M{ms.reset_mode}")
    for mode in ms.factors:
        Probe(ctx, f"the move in M{mode}", "10.7.motor.rates-scaled").script(
            [f"M{mode}", "A2", "V400", "L" + vector(ctx, *MODE_MOVE), 0.5])
        setup(ctx, "L" + vector(ctx, *(-d for d in MODE_MOVE)))
        _rest(ctx)
        setup(ctx, f"M{ms.reset_mode}")
    ctx.expect(position(ctx) == start, "the axes are back where the case found them",
               observed=position(ctx), expected=start, rule="10.7.motor.modes")
