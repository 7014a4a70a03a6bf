"""Spec section 9, Reset state: the cases that check it.

What power-on and `J` leave."""

from __future__ import annotations

from conformance.case.context import CaseContext, case
from conformance.cases._kit import (
    answers,
    code,
    configured,
    finished,
    fresh_reset,
    index,
    index_moved,
    position,
    setup,
    show,
    vector,
)
from conformance.link.account import Spent
from conformance.motion.probe import Probe
from gve_fixtures.protocol import ErrorCode


@case("9.reset.after-j",
      rules=("10.cmd.restart", "9.reset.state", "8.index.answer", "2.link.ready-after-restart"),
      destructive=True,
      timing=True)
def after_j(ctx: CaseContext) -> None:
    """J answers a plain 0 and restores the reset state after about 2 s."""
    link = ctx.link
    link.read_index()             # the form the unit writes the index in, read before J
    setup(ctx, "SW2,2B")
    setup(ctx, "L" + vector(ctx, 16))
    finished(ctx, 30)
    answers(ctx, link.send("J"), "0", "J → 0", rule="10.cmd.restart")
    link.wait(2.5, Spent.MANUAL)
    answers(ctx, link.send("SR2"), "0,00", "ST2 reset", rule="9.reset.state")
    # read in the form the unit writes it (8.index.decimal is graded where @ is)
    after = link.read_index()
    ctx.expect(after == 1, "the index restarted at 0", observed=after, expected=1,
               rule="8.index.answer")
    ctx.expect(position(ctx) == [0, 0, 0], "position zeroed", rule="9.reset.state")


@case("9.reset.after-power-on", rig=True, rules=("9.reset.state",), timing=True)
def after_power_on(ctx: CaseContext) -> None:
    """The rig's power-on restores the reset state as `J` does, the checksum mode too:
    a unit left summing and with ST2 written answers a plain `SR2` 0,00 after it."""
    link = ctx.link
    summing = "%" in ctx.profile.commands
    if summing:
        setup(ctx, "%+")
    setup(ctx, "SW2,2B")
    link.rig.power_on()
    link.checksums = False              # the host's side of the reset state (spec 9)
    link.wait(2.5, Spent.MANUAL)
    answers(ctx, link.send("SR2"), "0,00",
            "after power-on ST2 reset" + (", the frame taken without a checksum"
                                          if summing else ""), rule="9.reset.state")


@case("9.reset.gve54-sixteenths", requires=("M",), rules=("9.reset.gve54-motor",))
def gve54_reset(ctx: CaseContext) -> None:
    fresh_reset(ctx)
    setup(ctx, "L3,0,0")
    finished(ctx, 10)
    ctx.expect_equal(position(ctx), [3, 0, 0], "after reset a step is a sixteenth (MF)")
    answers(ctx, ctx.link.send("MD"), "0", "half current (MD) is a mode it takes")


@case("9.reset.measured-defaults", rules=("9.reset.state", "9.reset.decided", "9.reset.brake"),
      timing=True)
def reset_motion(ctx: CaseContext) -> None:
    """A20, V1000 (9.reset.state); VN, XM100, VL = max, T = 5 ms (9.reset.decided); B = max:
    a junction at the full rate (9.reset.brake), each measured from the reset state."""
    fresh_reset(ctx)
    Probe(ctx, "reset A and V", "9.reset.state").script(["L500,0,0", 0.7])
    Probe(ctx, "reset VN, XM, VL, T", "9.reset.decided").script(
        ["L300,-400,0", [300, -400, 0], "L10,0,0", 0.03])
    Probe(ctx, "reset B", "9.reset.brake").script(["C-300,400,0", "C-200,0,0", 0.7])


@case("9.reset.mpg-enabled", requires=("Y",), destructive=True,
      rules=("9.reset.mpg", "5.moving.definition", "10.cmd.mpg", "10.cmd.restart",
             "9.reset.mpg-parameters", "9.reset.mpg-held-at-reset"))
def mpg_moving(ctx: CaseContext) -> None:
    link = ctx.link
    # enabled, every parameter in range (M114 12); with one out of range and no leave to
    # write it, what the MPG mode does is a reading
    ready = configured(ctx, "mpg", required=False)
    rule = "9.reset.mpg" if ready else "9.reset.mpg-parameters"
    answers(ctx, link.send("J"), "0", "J → 0", rule="10.cmd.restart")
    link.wait(2.5, Spent.MANUAL)
    _mpg_on(ctx, "after J", "10.cmd.mpg" if ready else rule)
    code(ctx, link.send("L" + vector(ctx, 10)), ErrorCode.BUSY,
         "vectors are refused: 7", rule=rule)
    for body in ("D", "K", "R", "EW40,00", "EFW44,1", "EUW48,1"):
        code(ctx, link.send(body), ErrorCode.BUSY, f"{body} while the MPG holds RUN → 7",
             rule="5.moving.definition")
    answers(ctx, link.send("Y-"), "0,Y-", "Y- turns the MPG off", rule="10.cmd.mpg")
    # an MPG that did not take effect let the vector run: it has ended by the idiom's 0
    finished(ctx, 30, lambda r: r.code != ErrorCode.QUEUE_FULL)
    answers(ctx, link.send("SR6"), "0,00", "and RUN clears", rule="10.cmd.mpg")


def _mpg_on(ctx: CaseContext, shown: str, rule: str) -> None:
    """The MPG the EEPROM enables on after a restart: holding RUN at once (the reset's `&`,
    9.reset.mpg-held-at-reset [D]), or, to a reader of M114 13.5's ST6 = 00, from a `Y&`
    sent, which ``rule`` judges ("Při odeslání Y+ nebo Y& je stav stroje v chodu")."""
    link = ctx.link
    r = link.send("SR6")
    held = r is not None and r.values == ["40"]
    ctx.expect(held, f"{shown} the MPG holds RUN = 1", observed=show(r), expected="0,40",
               rule="9.reset.mpg-held-at-reset")
    if held:
        return
    answers(ctx, link.send("Y&"), "0,Y&", f"{shown}: Y& turns the MPG on", rule=rule)
    r = link.send("SR6")
    ctx.expect(r is not None and r.values == ["40"], f"{shown}: with Y& sent it holds RUN = 1",
               observed=show(r), expected="0,40", rule=rule)


# a unit whose EEPROM 06 is known to be as shipped (FF): the emulator's
@case("9.reset.mpg-inert.as-shipped", requires=("Y",), rig=True, rules=("9.reset.mpg-inert",))
def mpg_inert(ctx: CaseContext) -> None:
    configured(ctx, "mpg-off")
    answers(ctx, ctx.link.send("SR6"), "0,00", "MPG mode after reset, EEPROM 06 = FF: inert")
    answers(ctx, ctx.link.send("L" + vector(ctx, 10)), "0", "and vectors are accepted")


@case("9.reset.state",
      rules=("9.reset.state", "8.index.counts"))
def reset_state(ctx: CaseContext) -> None:
    """After reset: ST0..ST6 = 00, position 0, outputs FF, checksums off."""
    fresh_reset(ctx)
    before = index(ctx)
    for n in range(7):
        answers(ctx, ctx.link.send(f"SR{n}"), "0,00", f"ST{n} = 00", rule="9.reset.state")
    here = position(ctx)
    ctx.expect(here == [0, 0, 0], "position 0", observed=here, expected=[0, 0, 0],
               rule="9.reset.state")
    index_moved(ctx, before, 8, "the index counted the SR and PF frames", rule="8.index.counts")


def _mpg_values(ctx: CaseContext) -> list[tuple[int, bool]]:
    """Every value EEPROM's MPG byte lists as enabling, and the values beside each (and
    0, and the erased byte) that it does not list: (value, enables)."""
    mpg, erased = ctx.profile.mpg, ctx.profile.eeprom.erased
    listed = set(mpg.enabling_values)
    beside = {(v + d) & 0xFF for v in listed for d in (-1, 1)} | {0x00, erased}
    return sorted([(v, True) for v in listed] + [(v, False) for v in beside - listed])


@case("9.reset.mpg-enabling-values", requires=("Y",), destructive=True,
      rules=("9.reset.mpg", "10.cmd.mpg", "9.reset.mpg-inert", "9.reset.mpg-held-at-reset"))
def mpg_values(ctx: CaseContext) -> None:
    """Each value of the MPG enable byte the manual lists (M114 12.2: 01, 02, 81, 82)
    holds the axes after J, or from a `Y&` sent (RUN = 1, vectors 7), and `Y-`, `Y&`,
    `Y+` switch it off and on; every value beside them leaves the MPG inert, `Y&` too."""
    mpg, link = ctx.profile.mpg, ctx.link
    enable = "%02X" % mpg.enable_address
    # every other MPG parameter in range first (M114 12: otherwise "the MPG cannot be
    # used"), so that only the enable byte decides
    configured(ctx, "mpg")
    for value, enables in _mpg_values(ctx):
        answers(ctx, link.send("Y-"), "0,Y-", "Y- before the EEPROM write", rule="10.cmd.mpg")
        setup(ctx, f"EW{enable},{value:02X}")
        setup(ctx, "J")
        link.wait(ctx.profile.restart_ms / 1000 + 0.5, Spent.MANUAL)     # spec 2
        shown = f"EEPROM {enable} = {value:02X}"
        if enables:
            _mpg_on(ctx, f"{shown}: after J", "10.cmd.mpg")
            code(ctx, link.send("L" + vector(ctx, 1)), ErrorCode.BUSY,
                 f"{shown}: a vector → 7", rule="9.reset.mpg")
            answers(ctx, link.send("Y-"), "0,Y-", f"{shown}: Y- turns it off",
                    rule="10.cmd.mpg")
            answers(ctx, link.send("SR6"), "0,00", f"{shown}: after Y- RUN = 0",
                    rule="10.cmd.mpg")
            for on in ("Y&", "Y+"):
                answers(ctx, link.send(on), f"0,{on}", f"{shown}: {on}", rule="10.cmd.mpg")
                r = link.send("SR6")
                ctx.expect(r is not None and r.values == ["40"], f"{shown}: {on} holds RUN = 1",
                           observed=show(r), expected="0,40", rule="10.cmd.mpg")
                answers(ctx, link.send("Y-"), "0,Y-", f"{shown}: Y-", rule="10.cmd.mpg")
            continue
        r = link.send("SR6")
        ctx.expect(r is not None and r.values == ["00"], f"{shown}: MPG inert, ST6 = 00",
                   observed=show(r), expected="0,00", rule="9.reset.mpg-inert")
        code(ctx, link.send("L" + vector(ctx, 1)), ErrorCode.OK,
             f"{shown}: not a listed value, the MPG is not allowed: after J a vector is taken",
             rule="9.reset.mpg")
        link.poll("L" + vector(ctx, -1), lambda r: r.code != ErrorCode.QUEUE_FULL, 10)
        finished(ctx, 10, lambda r: r.code != ErrorCode.QUEUE_FULL)
        # where the MPG is not allowed (M114 12.2 "jiná: MPG nepovoleno"), what Y& answers
        # is silent: a reader may refuse it out of range; and one may hold RUN from a Y&
        # sent all the same (13.6.8 "Při odeslání Y+ nebo Y& je stav stroje v chodu"):
        # the [D] reading's rule judges both
        answers(ctx, link.send("Y&"), "0,Y&", f"{shown}: Y&", rule="9.reset.mpg-inert")
        code(ctx, link.send("L" + vector(ctx, 1)), ErrorCode.OK,
             f"{shown}: not a listed value: with Y& sent a vector is still taken",
             rule="9.reset.mpg-inert")
        link.poll("L" + vector(ctx, -1), lambda r: r.code != ErrorCode.QUEUE_FULL, 10)
        finished(ctx, 10, lambda r: r.code != ErrorCode.QUEUE_FULL)
    answers(ctx, link.send("Y-"), "0,Y-", "the MPG off at the end", rule="10.cmd.mpg")
