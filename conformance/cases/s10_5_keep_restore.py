"""Spec section 10.5, KEEP / RESTORE: the cases that check it.

Saving the queue to lift the tool mid-job and restoring it afterwards."""

from __future__ import annotations

from conformance.case.context import CaseContext, case
from conformance.cases._kit import (
    answers,
    code,
    finished,
    fresh_reset,
    halted_line,
    halted_with_queue,
    position,
    setup,
    show,
    still_seconds,
    vector,
)
from conformance.link.account import Spent
from gve_fixtures.protocol import ErrorCode


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
    finished(ctx, 10)
    answers(ctx, link.send("L" + vector(ctx, 2)), "0", "and L is accepted once idle")


@case("10.5.keep.one-level",
      rules=("10.5.keep.one-level", "10.5.keep.one-level-info"))
def one_level(ctx: CaseContext) -> None:
    halted_with_queue(ctx)
    setup(ctx, "K")      # saves the halted queue, INTA = 1
    # the point itself: the GVE84/GVE114 manuals allow a K without its R only once, so
    # a unit there may refuse the second one (the GVE54's says the first save is lost)
    rule = "10.5.keep.one-level" if ctx.profile.keep != "single-L" else \
        "10.5.keep.one-level-info"
    answers(ctx, ctx.link.send("K"), "0", "a second K saves the now empty queue over it",
            rule=rule)
    answers(ctx, ctx.link.send("R"), "0", "R brings back the second (empty) save", rule=rule)
    answers(ctx, ctx.link.send("SR6"), "0,00", "ST6 as the second K saved it", rule=rule)


@case("10.5.keep.partial-vector",
      rules=("10.5.keep.saves", "10.5.restore.exact"))
def partial(ctx: CaseContext) -> None:
    """K keeps the rest of the interrupted vector: after R and G no step is lost."""
    halted_with_queue(ctx)
    setup(ctx, "K")
    setup(ctx, "L" + vector(ctx, 0, 0, -100))
    finished(ctx, 30)
    setup(ctx, "L" + vector(ctx, 0, 0, 100))
    finished(ctx, 30)
    ctx.link.send("R")
    ctx.link.send("G")
    finished(ctx, 60)
    ctx.expect_equal(position(ctx), [990, 0, 0], "the job finished exactly",
                     rule="10.5.restore.exact")


@case("10.5.keep.refused-while-moving",
      rules=("5.code.busy-moving", "10.5.keep.saves"))
def moving(ctx: CaseContext) -> None:
    """K and R are not possible while moving (7)"""
    # half the default envelope: a save an earlier case gave back may run again at R
    setup(ctx, "C" + vector(ctx, 1000))
    ctx.link.wait(0.2, Spent.MOTION)         # the vector under way
    code(ctx, ctx.link.send("K"), ErrorCode.BUSY, "K while moving", rule="5.code.busy-moving")
    code(ctx, ctx.link.send("R"), ErrorCode.BUSY, "R while moving", rule="5.code.busy-moving")
    ctx.link.send("H")


@case("10.5.keep.saves-st6",
      rules=("10.5.keep.saves", "10.5.restore.exact", "4.response.inta-after-command"))
def saves(ctx: CaseContext) -> None:
    """K saves the queue and ST4..ST6 and clears them; R brings them back."""
    halted_with_queue(ctx)
    r = ctx.link.send("K")
    code(ctx, r, ErrorCode.OK, "K is accepted", rule="10.5.keep.saves")
    ctx.expect(r is not None and not r.inta, "K's answer shows INTA cleared",
               observed=show(r), expected="0", rule="4.response.inta-after-command")
    answers(ctx, ctx.link.send("SR6"), "0,00", "ST6 cleared after K", rule="10.5.keep.saves")
    r = ctx.link.send("R")
    code(ctx, r, ErrorCode.OK, "R is accepted", rule="10.5.restore.exact")
    ctx.expect(r is not None and r.inta, "R's answer shows the INTA it restored",
               observed=show(r), expected="8", rule="4.response.inta-after-command")
    r = ctx.link.send("SR6")
    ctx.expect(r is not None and r.values[:1] == ["D0"], "ST6 as saved",
               observed=show(r), expected="8,D0", rule="10.5.restore.exact")


@case("10.5.keep.single-l",
      rules=("10.5.keep.c-refused", "10.5.keep.single-l"),
      applies=lambda p: p.keep == "single-L")
def single_l(ctx: CaseContext) -> None:
    """After K the GVE84/GVE114 queue takes only L (a C answers 4)"""
    halted_with_queue(ctx)
    setup(ctx, "K")
    code(ctx, ctx.link.send("C" + vector(ctx, 10)), ErrorCode.SYNTAX, "C after K → 4",
         rule="10.5.keep.c-refused")
    code(ctx, ctx.link.send("L" + vector(ctx, 10)), ErrorCode.OK, "L after K → 0",
         rule="10.5.keep.single-l")


@case("10.5.restore.empty",
      rules=("10.5.restore.pops",))
def restore_empty(ctx: CaseContext) -> None:
    """R with nothing saved restores an empty save and answers 0."""
    fresh_reset(ctx)
    answers(ctx, ctx.link.send("R"), "0", "R at reset")
    ctx.expect(position(ctx) == [0, 0, 0], "nothing moved")


@case("10.5.restore.save-emptied", rules=("10.5.restore.pops",))
def save_emptied(ctx: CaseContext) -> None:
    link = ctx.link
    halted_line(ctx, 1000, 0.3)
    setup(ctx, "K")
    setup(ctx, "R", expect="8")
    setup(ctx, "G")
    link.poll("SR6", lambda r: r.values == ["00"], 10)
    answers(ctx, link.send("R"), "0", "a second R restores the empty save")
    code(ctx, link.send("G"), ErrorCode.NOTHING_TO_GO, "nothing to resume: G → 6")
    link.wait(still_seconds(ctx))
    ctx.expect_equal(position(ctx), [1000, 0, 0], "the remainder ran once")
