"""Spec section 10.4, HALT, GO, DELETE: the cases that check it.

Stopping, resuming and discarding motion."""

from __future__ import annotations

from conformance.case.context import CaseContext, case
from conformance.cases._kit import (
    answers,
    code,
    finished,
    halted_with_queue,
    measured_case,
    position,
    setup,
    show,
    still_seconds,
    vector,
)
from conformance.link.account import Spent
from gve_fixtures.protocol import ErrorCode, St6

# id -> (rules (the first judges the readings), commands it requires, families, scenario)
SCENARIOS: dict[str, tuple[tuple[str, ...], tuple[str, ...], tuple[str, ...], list]] = {
    # H brakes on the ramp and answers at rest; G resumes from rest (10.4)
    "10.4.measured.halt-ramp": (
        ("10.4.halt.ramp", "10.4.go.resume"), (), (),
        ["A3", "V1500", "C1500,0,0", 0.6, "H", 0.05, "G", 0.8]),
    # the HALT ramp runs on into the following vectors (10.4)
    "10.4.measured.halt-through-vectors": (
        ("10.4.halt.through-vectors",), (), (),
        ["A2", "V2000", "C500,0,0", "C500,0,0", "C500,0,0", 0.55, "H", 0.05, "G", 0.6]),
    # G resumes from the exact step, accelerating from rest (10.4)
    "10.4.measured.go-from-rest": (
        ("10.4.go.resume",), (), (),
        ["A2", "V1200", "L1400,0,0", 0.5, "H", 0.05, "G", 0.3]),
}


for _id, (_rules, _requires, _families, _scenario) in SCENARIOS.items():
    measured_case(_id, _rules, _requires, _families, _scenario)


@case("10.4.delete.clears",
      rules=("10.4.delete",))
def delete(ctx: CaseContext) -> None:
    halted_with_queue(ctx)
    here = position(ctx)
    answers(ctx, ctx.link.send("D"), "0", "D after H")
    answers(ctx, ctx.link.send("SR6"), "0,00", "ST6 cleared")
    ctx.link.wait(still_seconds(ctx))
    ctx.expect_equal(position(ctx), here, "position unchanged")


@case("10.4.delete.refused-while-moving",
      rules=("10.4.delete", "5.code.busy-moving"))
def delete_moving(ctx: CaseContext) -> None:
    """D while moving answers 7."""
    setup(ctx, "C" + vector(ctx, 2000))
    ctx.link.wait(0.2, Spent.MOTION)         # the vector under way
    code(ctx, ctx.link.send("D"), ErrorCode.BUSY, "D while moving → 7", rule="10.4.delete")
    ctx.link.send("H")


@case("10.4.go.empty-queue", rules=("10.4.go.empty",))
def go_empty(ctx: CaseContext) -> None:
    link = ctx.link
    setup(ctx, "H", expect="8")
    answers(ctx, link.send("G"), "0", "G with an empty queue clears INTA")
    answers(ctx, link.send("SR6"), "0,00", "INTA and INTCOM cleared")
    code(ctx, link.send("G"), ErrorCode.NOTHING_TO_GO, "and there is nothing more to resume")
    ctx.expect_equal(position(ctx), [0, 0, 0], "nothing moved")


@case("10.4.go.resumes-exactly",
      rules=("10.4.go.resume",))
def go(ctx: CaseContext) -> None:
    """G resumes the interrupted vector from the exact step: no step lost or gained; read
    at once, ST6 shows INTA and INTCOM cleared (RUN while the rest runs)."""
    halted_with_queue(ctx)
    answers(ctx, ctx.link.send("G"), "0", "G clears INTA")
    r = ctx.link.send("SR6")
    st6 = r.hex() if r is not None and r.ok and r.values else None
    ctx.expect(st6 is not None and not st6 & (St6.INTA | St6.INTCOM),
               "G that resumes held vectors clears INTA and INTCOM", observed=show(r),
               expected="0,40 (RUN) or 0,00: INTA and INTCOM clear")
    finished(ctx, 60)
    ctx.expect_equal(position(ctx), [990, 0, 0], "all three vectors completed")


@case("10.4.halt.answers-when-stopped",
      rules=("10.4.halt.ramp", "10.cmd.halt-answer", "10.3.st6.inta-run", "10.3.st6.bits"))
def halt(ctx: CaseContext) -> None:
    """H brakes on the ramp and answers (8) only once the motion has stopped."""
    halted_with_queue(ctx)
    first = position(ctx)
    ctx.link.wait(still_seconds(ctx))
    ctx.expect_equal(position(ctx), first, "no motion after H's answer", rule="10.4.halt.ramp")
    r = ctx.link.send("SR6")
    ctx.expect(r is not None and r.values[:1] == ["D0"], "ST6 = INTA+RUN+INTCOM, STOP clear",
               observed=show(r), expected="8,D0", rule="10.3.st6.inta-run")


@case("10.4.halt.in-final-deceleration",
      rules=("10.4.halt.ramp", "10.3.st6.inta-run", "10.2.motion.step-placement"),
      timing=True)
def halt_final(ctx: CaseContext) -> None:
    """H while the vector already decelerates at A to its end: the stop ramp at the same A
    ends there too. One step short is another placement of that ramp's steps (where a
    unit's own arithmetic lays the stop, the manuals do not say) [D], the step left held
    (RUN = 1); farther from the target, the ramp was not A's [M]."""
    link = ctx.link
    link.wait(0.03, Spent.MANUAL)            # the longest dwell T over (as the probe's rest)
    setup(ctx, "V1500")
    setup(ctx, "L" + vector(ctx, 0, 0, 245))
    link.wait(0.20, Spent.MOTION)            # the vector under way, into its deceleration
    answers(ctx, link.send("H"), "8", "H during the final deceleration", rule="10.4.halt.ramp")
    r = link.send("PF")
    short = r is not None and r.raw == b"8,0,0,244\r"
    answers(ctx, r, "8,0,0,245", "the vector ended on its target",
            rule="10.2.motion.step-placement" if short else "10.4.halt.ramp")
    if short:
        answers(ctx, link.send("SR6"), "8,D0", "INTA and INTCOM; RUN = 1: the step left is "
                "held", rule="10.3.st6.inta-run")
        return
    answers(ctx, link.send("SR6"), "8,90", "INTA and INTCOM; RUN = 0: nothing is left",
            rule="10.3.st6.inta-run")


def _axes(value: object, axes: int) -> bool:
    """Whether ``value`` (a rig's reading) gives a whole number for each of ``axes``."""
    return isinstance(value, list) and len(value) == axes \
        and all(type(v) is int for v in value)


@case("10.4.halt.at-rest-on-the-rig", rig=True, timing=True, rules=("10.4.halt.ramp",))
def halt_at_rest_on_the_rig(ctx: CaseContext) -> None:
    """H answers only when stopped, judged where the rig reads every axis (the GVE114's A
    too): from H's answer on, where each axis physically stands and its counter no longer
    change, and the counters are where the axes stand."""
    link = ctx.link
    axes = len(ctx.profile.axes)
    setup(ctx, "V1500")
    setup(ctx, "L" + ",".join(["1500"] + ["-700"] * (axes - 1)))
    link.wait(0.3, Spent.MOTION)             # the vector under way
    r = link.send("H")
    ctx.require(r is not None and r.inta, f"H answered {show(r)}")
    first = link.rig.state()
    link.wait(0.3)
    later = link.rig.state()
    axes_read = {key: (first.get(key), later.get(key)) for key in ("physical", "position")}
    # what the rig's state does not give is not tested (never a failure of the unit)
    missing = [key for key, reads in axes_read.items()
               if not all(_axes(v, axes) for v in reads)]
    for key, (was, now) in axes_read.items():
        if key not in missing:
            ctx.expect(was == now, f"from H's answer on, every axis's {key} stands still",
                       observed=f"{was} then {now}", expected="the same",
                       rule="10.4.halt.ramp")
    if "position" not in missing:
        here = position(ctx)
        ctx.expect(here is not None and here == later["position"][:3],
                   "PF reads the counters the rig reads", observed=here,
                   expected=later["position"][:3], rule="10.4.halt.ramp")
    setup(ctx, "D")
    ctx.require(not missing, "the rig's state gives no "
                + " and no ".join(repr(k) for k in missing)
                + f" for {axes} axes: that part of H's stop is not tested")
