"""Section 10, W: the reference run, on the test rig's switches and inputs. Never sent to
a real unit without --allow-destructive (the axis travels to its switch)."""

from __future__ import annotations

from conformance.case import CaseContext, case
from conformance.cases._kit import answers, position, setup
from gve_fixtures.protocol import SECOND


@case("10.cmd.reference.to-switch", rig=True, destructive=True, requires=("W",),
      rules=("10.cmd.reference", "10.cmd.reference-syntax", "2.link.answer-promptly"))
def to_switch(ctx: CaseContext) -> None:
    link = ctx.link
    link.rig.set_switch("X", -150)
    r = link.send("WX,-1000,2000,200,1000")
    answers(ctx, r, "0", "WX,-1000,2000,200,1000 finds the switch", rule="10.cmd.reference")
    took = None if r is None else (r.received_at - r.sent_at) / SECOND
    ctx.expect(took is not None and took >= 150 / 2000, "W answers once the axis has stopped",
               observed=f"{took} s", expected="at least the 75 ms to the switch",
               rule="2.link.answer-promptly")
    ctx.expect(position(ctx) == [0, 0, 0], "the counter is 0 where the switch releases",
               observed=position(ctx), expected=[0, 0, 0], rule="10.cmd.reference")
    link.rig.set_switch("X", None)
    link.rig.set_switch("Y", -100)
    answers(ctx, link.send("WY-1000,2000,200,1000"), "0",
            "WY-1000,... (no comma after the axis) is accepted too",
            rule="10.cmd.reference-syntax")
    ctx.expect(position(ctx) == [0, 0, 0], "Y's counter is 0 where its switch releases",
               observed=position(ctx), expected=[0, 0, 0], rule="10.cmd.reference")


@case("10.cmd.reference.inputs", rig=True, destructive=True, requires=("W",),
      rules=("10.cmd.reference-switch", "10.cmd.reference-fails"))
def inputs(ctx: CaseContext) -> None:
    link = ctx.link
    link.rig.set_input(1, 0xFD)              # IN1 grounded: Y's switch, active at polarity 0
    answers(ctx, link.send("WX,-100,1000,50,1000"), "5",
            "X watches IN0, which is not active: not found within 100 steps",
            rule="10.cmd.reference-fails")
    ctx.expect(position(ctx) == [-100, 0, 0], "X stayed where the travel ended",
               observed=position(ctx), expected=[-100, 0, 0], rule="10.cmd.reference-fails")
    answers(ctx, link.send("WY,-100,1000,50,1000"), "5",
            "Y watches IN1, active all the way back: still active after 50 steps back",
            rule="10.cmd.reference-switch")
    ctx.expect(position(ctx) == [-100, 50, 0], "Y stayed 50 steps back from where it found it",
               observed=position(ctx), expected=[-100, 50, 0], rule="10.cmd.reference-fails")
    link = ctx.fresh_link()
    link.rig.set_input(1, 0xFF)
    setup(ctx, "SW2,04")                     # Z's input IN2 active at log. 1: it is
    r = link.send("WZ,-100,1000,30,1000")
    answers(ctx, r, "5", "Z watches IN2 under the polarity rule (active at 1, reads 1)",
            rule="10.cmd.reference-switch")
    ctx.expect(position(ctx) == [0, 0, 30], "Z found it at once and backed off 30 steps",
               observed=position(ctx), expected=[0, 0, 30], rule="10.cmd.reference-switch")


