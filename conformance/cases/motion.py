"""Sections 10.1, 10.2, 10.4: the queue, L and C, motion, HALT/GO/DELETE."""

from __future__ import annotations

from conformance.case import CaseContext, case
from conformance.cases._kit import (
    answers,
    code,
    fill_queue,
    halted_with_queue,
    position,
    setup,
    show,
    vector,
)


@case("10.1.line.refused-while-busy",
      rules=("10.1.queue.line-alone", "5.code.queue-full"))
def l_busy(ctx: CaseContext) -> None:
    """L is accepted only when nothing is queued or running; otherwise 1."""
    setup(ctx, "C" + vector(ctx, 500))
    code(ctx, ctx.link.send("L" + vector(ctx, 10)), 1, "L while a C runs → 1")
    ctx.link.poll("L" + vector(ctx, 0), lambda r: r.code == 0, 30)
    ctx.expect(position(ctx) == [500, 0, 0], "the refused L did not move",
               observed=position(ctx), expected=[500, 0, 0], tag="always")


@case("10.1.line.wait-idiom",
      rules=("10.1.queue.wait-idiom",))
def idiom(ctx: CaseContext) -> None:
    setup(ctx, "L" + vector(ctx, 300))
    code(ctx, ctx.link.send("L" + vector(ctx, 0)), 1, "L0,0,0 while moving → 1")
    r = ctx.link.poll("L" + vector(ctx, 0), lambda r: r.code != 1, 30)
    code(ctx, r, 0, "L0,0,0 once idle → 0")
    ctx.expect(position(ctx) == [300, 0, 0], "the first L completed",
               observed=position(ctx), expected=[300, 0, 0])


@case("10.1.queue.executing-counts",
      rules=("10.1.queue.cont-buffer", "10.cmd.flags", "1.profile.buffer"))
def queue_full_flag(ctx: CaseContext) -> None:
    """The CONT buffer's size includes the executing vector; F shows bit 5 when full."""
    if fill_queue(ctx):
        r = ctx.link.send("F")
        ctx.expect(r is not None and r.values[:1] == ["F0"], "F = INTA + RUN + INTCOM + full",
                   observed=show(r), expected="8,F0")
    ctx.link.send("D")


@case("10.2.motion.targets-reached",
      rules=("10.1.queue.relative", "10.2.motion.step-placement"))
def targets(ctx: CaseContext) -> None:
    setup(ctx, "V5000")
    moves = [(100, -37, 5), (-250, 40, 0), (3, 3, -3)]
    for m in moves:
        setup(ctx, "C" + vector(ctx, *m))
    ctx.link.poll("L" + vector(ctx, 0), lambda r: r.code == 0, 60)
    expected = [sum(m[i] for m in moves) for i in range(3)]
    ctx.expect(position(ctx) == expected, "the sum of the vectors",
               observed=position(ctx), expected=expected, rule="10.1.queue.relative")
    ctx.step_train("the step train of the three vectors")


@case("10.4.halt.answers-when-stopped",
      rules=("10.4.halt.ramp", "10.cmd.halt-answer", "10.3.st6.inta-run", "10.3.st6.bits"))
def halt(ctx: CaseContext) -> None:
    """H brakes on the ramp and answers (8) only once the motion has stopped."""
    halted_with_queue(ctx)
    first = position(ctx)
    ctx.link.wait(0.5)
    ctx.expect(position(ctx) == first, "no motion after H's answer",
               observed=position(ctx), expected=first)
    r = ctx.link.send("SR6")
    ctx.expect(r is not None and r.values[:1] == ["D0"], "ST6 = INTA+RUN+INTCOM, STOP clear",
               observed=show(r), expected="8,D0")


@case("10.4.go.resumes-exactly",
      rules=("10.4.go.resume",))
def go(ctx: CaseContext) -> None:
    """G resumes the interrupted vector from the exact step: no step lost or gained."""
    halted_with_queue(ctx)
    answers(ctx, ctx.link.send("G"), "0", "G clears INTA")
    ctx.link.poll("L" + vector(ctx, 0), lambda r: r.code == 0, 60)
    ctx.expect(position(ctx) == [990, 0, 0], "all three vectors completed",
               observed=position(ctx), expected=[990, 0, 0])


@case("10.4.delete.clears",
      rules=("10.4.delete",))
def delete(ctx: CaseContext) -> None:
    halted_with_queue(ctx)
    here = position(ctx)
    answers(ctx, ctx.link.send("D"), "0", "D after H")
    answers(ctx, ctx.link.send("SR6"), "0,00", "ST6 cleared")
    ctx.link.wait(1.0)
    ctx.expect(position(ctx) == here, "position unchanged", observed=position(ctx),
               expected=here)


@case("10.4.delete.refused-while-moving",
      rules=("10.4.delete", "5.code.busy-moving"))
def delete_moving(ctx: CaseContext) -> None:
    """D while moving answers 7."""
    setup(ctx, "C" + vector(ctx, 2000))
    ctx.link.wait(0.2)
    code(ctx, ctx.link.send("D"), 7, "D while moving → 7")
    ctx.link.send("H")


@case("10.commands.zero-axis",
      rules=("10.cmd.set-axis", "10.cmd.zero"),
      requires=("NX",))
def set_axis(ctx: CaseContext) -> None:
    """!0NX100 sets the X counter; !0N zeroes every axis."""
    answers(ctx, ctx.link.send("NX100"), "0", "NX100")
    ctx.expect(position(ctx) == [100, 0, 0], "X = 100", observed=position(ctx))
    answers(ctx, ctx.link.send("N"), "0", "N")
    ctx.expect(position(ctx) == [0, 0, 0], "all zero", observed=position(ctx))
