"""Spec section 12, GVE114 spindle, address 7: the cases that check it.

The spindle speed the GVE114 takes at address 7."""

from __future__ import annotations

from conformance.case.context import CaseContext, case
from conformance.cases._kit import answers, code, show
from conformance.motion.probe import Probe
from gve_fixtures.protocol import ErrorCode


def spindle(ctx: CaseContext, value: int) -> None:
    """Setup: the spindle at ``value`` (its answer is judged by 12.spindle.address-7)."""
    r = ctx.link.send(f"V{value}", address=7)
    ctx.require(r is not None and r.ok, f"!7V{value} answered {show(r)}")


@case("12.spindle.address-7",
      rules=("12.spindle.speed", "12.spindle.commands"),
      tag="M-ex", rig=True,
      applies=lambda p: p.spindle is not None)
def address_7(ctx: CaseContext) -> None:
    """!7V<n> sets the spindle (per mille); V0 switches OUT0 off; !0V is the feed rate."""
    link = ctx.link
    speed = "12.spindle.speed"
    answers(ctx, link.send("V300", address=7), "0", "!7V300", rule=speed)
    ctx.expect_equal(link.rig.spindle(), 300, "spindle 300", rule=speed)
    outputs = link.rig.outputs()
    ctx.expect(outputs & 1 == 0, "OUT0 on", observed=outputs, rule=speed)
    answers(ctx, link.send("V0", address=7), "0", "!7V0", rule=speed)
    outputs = link.rig.outputs()
    ctx.expect(outputs & 1 == 1, "OUT0 off", observed=outputs, rule=speed)
    code(ctx, link.send("L1,0,0", address=7), ErrorCode.UNKNOWN, "address 7 takes no vectors",
         rule="12.spindle.commands")
    # and serves the EEPROM's reads as address 0 does (its commands, spec 12)
    if "ER" in ctx.profile.spindle.commands:
        here, there = link.send("ER10"), link.send("ER10", address=7)
        ctx.expect(there is not None and here is not None and there.ok
                   and there.values == here.values, "!7ER10 answers as !0ER10",
                   observed=show(there), expected=show(here), rule="12.spindle.commands")


@case("12.spindle.measured.feed-unchanged", timing=True,
      applies=lambda p: p.spindle is not None,
      rules=("12.spindle.feed-independent", "12.spindle.speed"))
def feed_unchanged(ctx: CaseContext) -> None:
    probe = Probe(ctx, "the feed rate V1500 after !7V900", "12.spindle.feed-independent")
    probe.send("V1500")
    spindle(ctx, 900)
    probe.run(["A10000", "L600,0,0", [600, 0, 0], "L-600,0,0", [0, 0, 0]])
    spindle(ctx, 0)
    probe.judge()


@case("12.spindle.unchanged-by-feed", rig=True, applies=lambda p: p.spindle is not None,
      rules=("12.spindle.feed-independent", "12.spindle.speed"))
def spindle_unchanged(ctx: CaseContext) -> None:
    link, rule = ctx.link, "12.spindle.feed-independent"
    answers(ctx, link.send("V300", address=7), "0", "!7V300", rule="12.spindle.speed")
    for feed in ("V40", "V2000", "V1000"):
        answers(ctx, link.send(feed), "0", f"!0{feed}", rule=rule)
        ctx.expect_equal(link.rig.spindle(), 300, f"the spindle still at 300 after !0{feed}",
                         rule=rule)
    answers(ctx, link.send("V0", address=7), "0", "!7V0", rule="12.spindle.speed")


@case("12.spindle.range-ends", rig=True, applies=lambda p: p.spindle is not None,
      rules=("12.spindle.speed", "5.code.range"))
def range_ends(ctx: CaseContext) -> None:
    """The spindle's range from the profile, at both ends and one beyond each: 0 switches
    OUT0 off, every value from 1 to the top switches it on (1 too), and a refused value
    changes neither the setting nor OUT0."""
    link, r = ctx.link, ctx.profile.spindle.range
    speed = "12.spindle.speed"
    for value in (r.lo + 1, r.hi, r.lo, r.hi, r.lo + 1, r.lo):
        answers(ctx, link.send(f"V{value}", address=7), "0", f"!7V{value}", rule=speed)
        ctx.expect_equal(link.rig.spindle(), value, f"!7V{value}: the spindle at {value}",
                         rule=speed)
        on = value > 0
        outputs = link.rig.outputs()
        ctx.expect(outputs & 1 == (0 if on else 1),
                   f"!7V{value}: OUT0 {'on' if on else 'off'}",
                   observed="%02X" % outputs,
                   expected=f"OUT0 {'on (bit 0 = 0)' if on else 'off (bit 0 = 1)'}",
                   rule=speed)
    answers(ctx, link.send(f"V{r.hi}", address=7), "0", f"!7V{r.hi}", rule=speed)
    for beyond in (r.hi + 1, r.lo - 1):
        code(ctx, link.send(f"V{beyond}", address=7), ErrorCode.RANGE, f"!7V{beyond} → 5",
             rule="5.code.range")
        spindle, outputs = link.rig.spindle(), link.rig.outputs()
        ctx.expect(spindle == r.hi and outputs & 1 == 0,
                   f"the refused !7V{beyond} left the spindle at {r.hi}, OUT0 on",
                   observed=f"{spindle}, outputs {outputs:02X}",
                   expected=f"{r.hi}, bit 0 clear", rule=speed)
    answers(ctx, link.send("V0", address=7), "0", "!7V0", rule=speed)
