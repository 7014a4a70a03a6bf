"""Sections 4, 10, 10.3, 10.4, 10.5: how commands act together — inputs that stay
active across G, D, K, R, J and power-on; ST6 written with SW; the KEEP save emptied by
R; F after K; a HALT during the final deceleration. Each case quotes its rule from
fixtures/rules.toml and replays the exchange the spec writes for it."""

from __future__ import annotations

from conformance.case import CaseContext, case
from conformance.cases._kit import answers, code, halted_line, position, setup, show, vector

IN0_ACTIVE = 0xFE          # IN0 grounded: active at the reset polarity 0 (spec 10.3)


def _interrupted_by_input(ctx: CaseContext) -> None:
    """Setup: IN0 enabled and active, so the unit is interrupted (INTA, ST4 bit 0)."""
    r = ctx.link.send("SW0,01")
    ctx.require(r is not None and r.code == 0 and r.inta, f"SW0,01 answered {show(r)}")


@case("10.3.inputs.level-after-clearing", hands=True,
      rules=("10.3.inputs.level-triggered", "4.response.inta-level", "10.5.restore.pops"))
def level_after_clearing(ctx: CaseContext) -> None:
    for body in ("G", "D", "K", "R"):
        ctx.fresh_link()
        with ctx.operator.grounded(1, 0, "the X reference input"):
            _after_clearing(ctx, body)


def _after_clearing(ctx: CaseContext, body: str) -> None:
    _interrupted_by_input(ctx)
    r = ctx.link.send(body)
    if body == "R":
        # nothing was kept: what R answers then is the restore rule's reading, the INTA
        # bit on that answer this case's
        code(ctx, r, 0, "R with nothing kept → 0", rule="10.5.restore.pops")
        ctx.expect(r is not None and r.inta is True, "R with the input still active: INTA "
                   "set on the answer", observed=show(r), expected="INTA bit set",
                   rule="4.response.inta-level")
    else:
        code(ctx, r, 0, f"{body} with the input still active → 8", inta=True,
             rule="4.response.inta-level")
    for n, value in ((6, "80"), (4, "01")):
        r = ctx.link.send(f"SR{n}")
        ctx.expect(r is not None and r.inta and r.values == [value],
                   f"after {body}: ST{n} set again at once", observed=show(r),
                   expected=f"8,{value}", rule="10.3.inputs.level-triggered")
    code(ctx, ctx.link.send("L" + vector(ctx, 300)), 0,
         f"after {body}: L is accepted and waits", inta=True,
         rule="10.3.inputs.level-triggered")
    ctx.link.wait(0.5)
    here = position(ctx)
    ctx.expect(here == [0, 0, 0], f"after {body}: nothing moved while the input is active",
               observed=here, expected=[0, 0, 0], rule="10.3.inputs.level-triggered")


@case("10.3.inputs.physical-across-restart", rig=True, destructive=True,
      rules=("10.3.inputs.physical",))
def physical(ctx: CaseContext) -> None:
    link = ctx.link
    link.rig.set_input(1, IN0_ACTIVE)
    answers(ctx, link.send("J"), "0", "J → 0", tag="D")
    link.wait(2.5)
    answers(ctx, link.send("I1"), "0,FE", "after J the grounded input still reads 0")
    link.rig.power_on()
    link.wait(2.5)
    answers(ctx, link.send("I1"), "0,FE", "after power-on the grounded input still reads 0")


@case("10.3.sw6.writing-st6", rules=("10.3.sw6.acts", "10.3.sw6.live-bits"))
def sw6(ctx: CaseContext) -> None:
    link = ctx.link
    code(ctx, link.send("SW6,80"), 0, "SW6,80 sets INTA", inta=True, rule="10.3.sw6.acts")
    code(ctx, link.send("L" + vector(ctx, 100)), 0, "L is accepted while INTA = 1", inta=True,
         rule="10.3.sw6.acts")
    link.wait(0.5)
    ctx.expect(position(ctx) == [0, 0, 0], "the vector waits for G", observed=position(ctx),
               expected=[0, 0, 0], rule="10.3.sw6.acts")
    link = ctx.fresh_link()
    halted_line(ctx, 300, 0.1)
    code(ctx, link.send("SW6,00"), 0, "SW6,00 clears INTA", inta=False, rule="10.3.sw6.acts")
    r = link.poll("SR6", lambda r: r.values == ["00"], 10)
    ctx.expect(r is not None, "RUN clears when the resumed vector ends", observed=show(r),
               expected="0,00", rule="10.3.sw6.live-bits")
    ctx.expect(position(ctx) == [300, 0, 0], "the vector resumed to its target",
               observed=position(ctx), expected=[300, 0, 0], rule="10.3.sw6.acts")
    code(ctx, link.send("L" + vector(ctx, 0)), 0, "idle again: L0,0,0 → 0",
         rule="10.3.sw6.live-bits")


@case("10.5.restore.save-emptied", rules=("10.5.restore.pops",))
def save_emptied(ctx: CaseContext) -> None:
    link = ctx.link
    halted_line(ctx, 1000, 0.3)
    setup(ctx, "K")
    setup(ctx, "R", expect="8")
    setup(ctx, "G")
    link.poll("SR6", lambda r: r.values == ["00"], 10)
    answers(ctx, link.send("R"), "0", "a second R restores the empty save")
    code(ctx, link.send("G"), 6, "nothing to resume: G → 6")
    link.wait(1.0)
    ctx.expect(position(ctx) == [1000, 0, 0], "the remainder ran once",
               observed=position(ctx), expected=[1000, 0, 0])


@case("10.cmd.flags-after-keep.one-vector", applies=lambda p: p.keep == "single-L",
      rules=("10.cmd.flags-after-keep",))
def flags_after_keep(ctx: CaseContext) -> None:
    setup(ctx, "K")
    setup(ctx, "L" + vector(ctx, 300))
    answers(ctx, ctx.link.send("F"), "0,60", "F after K and one L: RUN and queue full")


@case("10.4.halt.in-final-deceleration", rules=("10.4.halt.ramp", "10.3.st6.inta-run"),
      timing=True)
def halt_final(ctx: CaseContext) -> None:
    link = ctx.link
    link.wait(0.03)
    setup(ctx, "V1500")
    setup(ctx, "L" + vector(ctx, 0, 0, 245))
    link.wait(0.20)
    answers(ctx, link.send("H"), "8", "H during the final deceleration", rule="10.4.halt.ramp")
    answers(ctx, link.send("PF"), "8,0,0,245", "the vector ended on its target",
            rule="10.4.halt.ramp")
    answers(ctx, link.send("SR6"), "8,90", "INTA and INTCOM; RUN = 0: nothing is left",
            rule="10.3.st6.inta-run")


@case("10.4.go.empty-queue", rules=("10.4.go.empty",))
def go_empty(ctx: CaseContext) -> None:
    link = ctx.link
    setup(ctx, "H", expect="8")
    answers(ctx, link.send("G"), "0", "G with an empty queue clears INTA")
    answers(ctx, link.send("SR6"), "0,00", "INTA and INTCOM cleared")
    code(ctx, link.send("G"), 6, "and there is nothing more to resume")
    ctx.expect(position(ctx) == [0, 0, 0], "nothing moved", observed=position(ctx),
               expected=[0, 0, 0])


@case("5.code.busy-while-halted", rules=("5.code.busy-run-decided",), requires=("NX",))
def busy_halted(ctx: CaseContext) -> None:
    link = ctx.link
    halted_line(ctx, 1000, 0.2)
    answers(ctx, link.send("NX0"), "F", "N<axis> while the halted vector holds RUN → 7")
    if not ctx.target.real and "W" in ctx.profile.commands:   # W: never on real units
        answers(ctx, link.send("WX,-10,1000,10,1000"), "F", "W while RUN = 1 → 7")
    here = position(ctx)
    ctx.expect(here is not None and 0 < here[0] < 1000, "the refused commands moved nothing",
               observed=here, expected="between 0 and 1000")
