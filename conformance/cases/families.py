"""What one family has and the others lack (spec 1, 5, 6, 9, 10, 10.5, 10.7, 12): the
GVE114's hand wheel (MPG) and its address 7 sharing the checksum mode and index, the
interrupt inputs each family wires, the GVE54's motor modes and its full queue after K."""

from __future__ import annotations

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


def _gve114(p) -> bool:
    return p.family == "GVE114"


@case("10.cmd.mpg.modes", requires=("Y",), rules=("10.cmd.mpg",))
def mpg_modes(ctx: CaseContext) -> None:
    for c in ("+", "&", "-"):
        answers(ctx, ctx.link.send(f"Y{c}"), f"0,Y{c}", f"Y{c} answers the command back")


# a unit whose EEPROM 06 is known to be as shipped (FF): the emulator's
@case("9.reset.mpg-inert.as-shipped", requires=("Y",), rig=True, rules=("9.reset.mpg-inert",))
def mpg_inert(ctx: CaseContext) -> None:
    answers(ctx, ctx.link.send("SR6"), "0,00", "MPG mode after reset, EEPROM 06 = FF: inert")
    answers(ctx, ctx.link.send("L" + vector(ctx, 10)), "0", "and vectors are accepted")


@case("9.reset.mpg-enabled", requires=("Y",), destructive=True,
      rules=("9.reset.mpg", "5.moving.definition", "10.cmd.mpg"))
def mpg_moving(ctx: CaseContext) -> None:
    link = ctx.link
    setup(ctx, "EW06,01")                    # MPG enabled (spec 9, M114 12.2)
    answers(ctx, link.send("J"), "0", "J → 0", tag="D")
    link.wait(2.5)
    r = link.send("SR6")
    ctx.expect(r is not None and r.values == ["40"], "after J the MPG holds RUN = 1",
               observed=show(r), expected="0,40", rule="9.reset.mpg")
    code(ctx, link.send("L" + vector(ctx, 10)), 7, "vectors are refused: 7", rule="9.reset.mpg")
    for body in ("D", "K", "R", "EW40,00", "EFW44,1", "EUW48,1"):
        code(ctx, link.send(body), 7, f"{body} while the MPG holds RUN → 7",
             rule="5.moving.definition")
    answers(ctx, link.send("Y-"), "0,Y-", "Y- turns the MPG off", rule="10.cmd.mpg")
    answers(ctx, link.send("SR6"), "0,00", "and RUN clears", rule="10.cmd.mpg")


@case("6.checksum.address-7-shares", requires=("%",), applies=_gve114,
      rules=("6.checksum.spindle-shares",))
def spindle_shares(ctx: CaseContext) -> None:
    link = ctx.link
    before = index(ctx)                      # a used unit's index is wherever it is
    ctx.require(before is not None, "@ at address 0 gave no index")
    setup(ctx, "%+", checksum=False)
    code(ctx, link.send("?", address=7, checksum=False), 4,
         "address 7 is in checksum mode too: a frame without one → 4")
    r = link.send("@", address=7)
    want = (before + 1) % 256
    ctx.expect(r is not None and r.checksum_ok is True and r.code == 0 and r.dec() == want,
               "address 7 counts the index of address 0 (%+ counted, the unsummed ? not)",
               observed=show(r), expected=f"0,{want},XX")
    setup(ctx, "V1000")
    index_moved(ctx, before, 2, "a frame at address 0 moves it", address=7)


@case("1.profile.interrupt-inputs.wired", rig=True,
      rules=("1.profile.interrupt-inputs", "1.profile.interrupt-inputs-gve114",
             "10.3.status.meaning"))
def wired(ctx: CaseContext) -> None:
    p = ctx.profile
    rule = "1.profile.interrupt-inputs" + ("-gve114" if p.family == "GVE114" else "")
    for port, enable, cause, mask in ((1, 0, 4, p.low_mask), (2, 1, 5, p.high_mask)):
        for bit in range(8):
            link = ctx.fresh_link()
            r = link.send("SW%d,%02X" % (enable, 1 << bit))
            ctx.require(r is not None and r.code == 0, f"SW{enable} answered {show(r)}")
            # grounded once enabled: an interrupt whether inputs are level- or
            # edge-triggered (level is our reading [D])
            link.rig.set_input(port, 0xFF ^ (1 << bit))
            r = link.send(f"SR{cause}")
            ctx.require(r is not None and r.code == 0, f"SR{cause} answered {show(r)}")
            wired = bool(mask >> bit & 1)
            ctx.expect(r.inta == wired, f"IN{bit} of port I{port} "
                       f"{'interrupts' if wired else 'has no input behind it'}",
                       observed=show(r), expected="8,%02X" % (1 << bit) if wired else "0,00",
                       rule=rule)
            if wired:
                answers(ctx, r, "8,%02X" % (1 << bit),
                        f"ST{cause} names IN{bit} of port I{port}", rule="10.3.status.meaning")


@case("10.7.motor.modes-while-moving", requires=("M",),
      rules=("10.7.motor.busy", "10.7.motor.any-position"))
def motor_busy(ctx: CaseContext) -> None:
    link = ctx.link
    setup(ctx, "V5000")
    setup(ctx, "L1001,500,399")
    code(ctx, link.send("M4"), 7, "M while moving → 7", rule="10.7.motor.busy")
    link.poll("L0,0,0", lambda r: r.code == 0, 10)
    ctx.expect(position(ctx) == [1001, 500, 399], "in MF the counters count the steps",
               observed=position(ctx), expected=[1001, 500, 399], rule="10.7.motor.any-position")
    answers(ctx, link.send("M2"), "0", "a coarser mode at a position not divisible by 8",
            rule="10.7.motor.any-position")
    setup(ctx, "MF")
    setup(ctx, "L-1,0,1")
    link.poll("L0,0,0", lambda r: r.code == 0, 10)
    ctx.expect(position(ctx) == [1000, 500, 400], "the manual's example: L-1,0,1",
               observed=position(ctx), expected=[1000, 500, 400], rule="10.7.motor.any-position")
    answers(ctx, link.send("M4"), "0", "then M4", rule="10.7.motor.any-position")


@case("9.reset.gve54-sixteenths", requires=("M",), rules=("9.reset.gve54-motor",))
def gve54_reset(ctx: CaseContext) -> None:
    fresh_reset(ctx)
    setup(ctx, "L3,0,0")
    ctx.link.poll("L0,0,0", lambda r: r.code == 0, 10)
    ctx.expect(position(ctx) == [3, 0, 0], "after reset a step is a sixteenth (MF)",
               observed=position(ctx), expected=[3, 0, 0])
    answers(ctx, ctx.link.send("MD"), "0", "half current (MD) is a mode it takes")


@case("10.5.keep.gve54-full-queue", applies=lambda p: p.keep == "full",
      rules=("10.5.keep.gve54-full",))
def gve54_full(ctx: CaseContext) -> None:
    link = ctx.link
    setup(ctx, "H", expect="8")
    setup(ctx, "C" + vector(ctx, 5), expect="8")
    setup(ctx, "K")
    for i in range(3):
        answers(ctx, link.send("C" + vector(ctx, 1)), "0", f"C {i + 1} after K is accepted")
    answers(ctx, link.send("F"), "0,40", "three vectors do not fill the queue")
    link.poll("L0,0,0", lambda r: r.code == 0, 10)
    answers(ctx, link.send("L" + vector(ctx, 2)), "0", "and L is accepted once idle")
