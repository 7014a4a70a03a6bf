"""Sections 10, 12: settings that share nothing in the manuals stay apart. The GVE114's
spindle (`!7V`) and the feed rate (`!0V`), each axis's `VL`, and `XM` against `V`: the
one set, the motion (or the spindle) measured shows the other as it was."""

from __future__ import annotations

from conformance.case import CaseContext, case
from conformance.cases._kit import answers, show
from conformance.motion.probe import Probe

#: per-axis limits, each its own: a limit taken from another axis changes every move
LIMITS = (600, 1200, 1800, 2400)
#: a move along each axis alone, there and back (commanded steps), then where it ends;
#: on the GVE114 A leads X, which shows A's limit in X's counter
AXIS_MOVES = ((600, 0, 0), (0, 600, 0), (0, 0, 600))
A_MOVE = (100, 0, 0, 600)


@case("10.cmd.measured.axis-limits-own-axis", timing=True, requires=("VL",),
      rules=("10.cmd.axis-limits-own-axis", "10.cmd.axis-limits", "10.2.motion.axis-caps"))
def axis_limits(ctx: CaseContext) -> None:
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


def spindle(ctx: CaseContext, value: int) -> None:
    """Setup: the spindle at ``value`` (its answer is judged by 12.spindle.address-7)."""
    r = ctx.link.send(f"V{value}", address=7)
    ctx.require(r is not None and r.code == 0, f"!7V{value} answered {show(r)}")


@case("12.spindle.unchanged-by-feed", rig=True, applies=lambda p: p.spindle is not None,
      rules=("12.spindle.feed-independent", "12.spindle.speed"))
def spindle_unchanged(ctx: CaseContext) -> None:
    link, rule = ctx.link, "12.spindle.feed-independent"
    answers(ctx, link.send("V300", address=7), "0", "!7V300", rule="12.spindle.speed")
    for feed in ("V40", "V2000", "V1000"):
        answers(ctx, link.send(feed), "0", f"!0{feed}", rule=rule)
        ctx.expect(link.rig.spindle() == 300, f"the spindle still at 300 after !0{feed}",
                   observed=link.rig.spindle(), expected=300, rule=rule)
    answers(ctx, link.send("V0", address=7), "0", "!7V0", rule="12.spindle.speed")
