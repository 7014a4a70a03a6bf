"""Section 10.3: status words, F, inputs and interrupts."""

from __future__ import annotations

from conformance.case import CaseContext, case
from conformance.cases._kit import answers, code, position, setup, show, vector


@case("10.3.status.all-bits-stored",
      rules=("10.3.status.all-bits", "10.cmd.status-words"),
      tag="D", source="spec 10.3 [D]; M84 12.5.8 SW1,3F",
      rule="Every status word stores all 8 bits as written")
def all_bits(ctx: CaseContext) -> None:
    for n, value in ((2, "2B"), (3, "FF"), (5, "80"), (1, "3F"), (0, "A2")):
        r = ctx.link.send(f"SW{n},{value}")     # may interrupt: only the code matters here
        ctx.require(r is not None and r.code == 0, f"SW{n},{value} answered {show(r)}")
        r = ctx.link.send(f"SR{n}")
        ctx.expect(r is not None and r.values == [value], f"SR{n} after SW{n},{value}",
                   observed=show(r), expected=value, rule="10.3.status.all-bits")


@case("10.3.status.run-bit",
      rules=("10.3.st6.bits", "10.3.st6.inta-run"),
      tag="M", source="M84 12.5.11",
      rule="ST6 bit 6 (RUN) is set while a vector is processed and clear when idle")
def run_bit(ctx: CaseContext) -> None:
    setup(ctx, "L" + vector(ctx, 500))
    r = ctx.link.send("SR6")
    ctx.expect(r is not None and r.values[:1] == ["40"], "RUN while moving",
               observed=show(r), expected="0,40")
    ctx.link.poll("L" + vector(ctx, 0), lambda r: r.code == 0, 30)
    answers(ctx, ctx.link.send("SR6"), "0,00", "idle again")


@case("10.3.status.inputs-read-ff",
      rules=("10.3.inputs.idle-level", "10.cmd.inputs"),
      tag="D", source="spec 10.3 [D]",
      rule="Input ports read FF with nothing connected")
def inputs(ctx: CaseContext) -> None:
    answers(ctx, ctx.link.send("I1"), "0,FF", "I1 with nothing connected",
            rule="10.3.inputs.idle-level")


@case("10.3.interrupt.stops-motion",
      rules=("10.3.inputs.interrupt", "10.3.status.meaning"),
      tag="M", source="M84 12.5.11", rig=True,
      rule="An enabled active input stops the motion, sets its cause bit and INTA")
def interrupt(ctx: CaseContext) -> None:
    link = ctx.link
    setup(ctx, "SW0,01")
    setup(ctx, "C" + vector(ctx, 3000))
    link.wait(0.3)
    link.rig.set_input(1, 0xFE)          # IN0 grounded: active at polarity 0
    link.wait(1.0)
    here = position(ctx)
    link.wait(0.5)
    ctx.expect(position(ctx) == here, "stopped", observed=position(ctx), expected=here,
               rule="10.3.inputs.interrupt")
    r = link.send("SR4")
    ctx.expect(r is not None and r.inta and r.values[:1] == ["01"], "ST4 bit 0, INTA",
               observed=show(r), expected="8,01", rule="10.3.status.meaning")


@case("10.3.interrupt.polarity",
      rules=("10.3.inputs.polarity", "4.response.inta-level"),
      tag="M", source="M84 12.5.11", hands=True,
      rule="An input is active when its level equals its polarity bit")
def polarity(ctx: CaseContext) -> None:
    link = ctx.link
    ctx.operator.release(1, 0, "the X reference input")     # unconnected: reads 1
    setup(ctx, "SW0,01")                 # IN0 enabled; unconnected (1) is inactive at 0
    # IN0 active at log. 1: the unconnected input becomes active, an interrupt whether
    # inputs are level- or edge-triggered (level is our reading [D])
    r = link.send("SW2,01")
    ctx.expect(r is not None and r.code == 0 and r.inta, "making it active interrupts at once",
               observed=show(r), expected="8", rule="4.response.inta-level")
    r = link.send("SR4")
    ctx.expect(r is not None and r.inta and r.values[:1] == ["01"],
               "an unconnected input with polarity 1 interrupts at once", observed=show(r),
               expected="8,01", rule="10.3.inputs.polarity")


@case("10.3.flags.f-command",
      rules=("10.cmd.flags", "3.params.none-expected"),
      tag="M", source="M84 12.5.11",
      rule="F answers ST6 with bit 5 = queue full")
def f_idle(ctx: CaseContext) -> None:
    answers(ctx, ctx.link.send("F"), "0,00", "F when idle", rule="10.cmd.flags")
    code(ctx, ctx.link.send("F1"), 4, "F takes no parameters", rule="3.params.none-expected")
