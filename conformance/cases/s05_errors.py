"""Spec section 5, Error codes: the cases that check it.

The eight codes of the response and which condition raises which."""

from __future__ import annotations

from conformance.case.context import CaseContext, case
from conformance.cases._kit import (
    answers,
    code,
    fill_queue,
    finished,
    halted_line,
    halted_with_queue,
    position,
    setup,
    vector,
)
from conformance.link.account import Spent
from gve_fixtures.protocol import ErrorCode


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


@case("5.errors.busy",
      rules=("5.code.busy-moving", "5.code.busy-run", "5.moving.definition"))
def busy(ctx: CaseContext) -> None:
    """D, K, R, N while a vector runs answer 7."""
    setup(ctx, "V1000")
    setup(ctx, "C" + vector(ctx, 1500))      # 1.5 s at V1000: moving for every probe
    ctx.link.wait(0.3, Spent.MOTION)         # (the vector under way, as halted_line waits)
    for body, rule in (("D", "5.code.busy-moving"), ("K", "5.code.busy-moving"),
                       ("R", "5.code.busy-moving"), ("N", "5.code.busy-run")):
        code(ctx, ctx.link.send(body), ErrorCode.BUSY, f"{body} while moving → 7", rule=rule)
    ctx.link.send("H")


@case("5.errors.go-without-inta",
      rules=("5.code.nothing-to-go", "10.4.go.without-inta"))
def go_idle(ctx: CaseContext) -> None:
    """G while INTA = 0 answers 6 and does nothing."""
    code(ctx, ctx.link.send("G"), ErrorCode.NOTHING_TO_GO, "G on an idle unit → 6",
         rule="5.code.nothing-to-go")


@case("5.errors.n-while-run",
      rules=("5.code.busy-run", "5.moving.after-halt"))
def n_run(ctx: CaseContext) -> None:
    """N is refused (7) while interrupted vectors still hold RUN = 1."""
    halted_with_queue(ctx)
    code(ctx, ctx.link.send("N"), ErrorCode.BUSY, "N after H with the rest queued", inta=True,
         rule="5.code.busy-run")
    # K and D after H are the manual's own (its KEEP example, "for deleting the rest of
    # the queue after an interruption"); R while halted vectors hold RUN is our reading
    # of "nelze použít za chodu" (a unit may refuse it with 7 while RUN = 1)
    setup(ctx, "K", expect="0")
    setup(ctx, "L" + vector(ctx, 0, 0, 50))
    setup(ctx, "H", expect="8")
    code(ctx, ctx.link.send("R"), ErrorCode.OK, "R after H with the L after K halted",
         inta=True, rule="5.moving.after-halt")


@case("5.errors.ok",
      rules=("5.code.ok", "10.cmd.vector", "3.params.commas"),
      tag="M-ex")
def ok(ctx: CaseContext) -> None:
    """An accepted command answers 0."""
    answers(ctx, ctx.link.send("L" + vector(ctx, 100)), "0", "L100,0,0 on an idle unit",
            rule="5.code.ok")


@case("5.errors.out-of-range",
      rules=("5.code.range", "10.cmd.status-words", "10.cmd.modal", "10.cmd.accel-range"))
def out_of_range(ctx: CaseContext) -> None:
    # A0: the accelerations' range is our reading [D]; the others the manual's
    for body, rule in (("SW8,F1", "5.code.range"), ("T25", "10.cmd.modal"),
                       ("A0", "10.cmd.accel-range"), ("SR7", "10.cmd.status-words")):
        code(ctx, ctx.link.send(body), ErrorCode.RANGE, f"{body} → 5", rule=rule)


@case("5.errors.queue-full",
      rules=("5.code.queue-full", "1.profile.buffer", "10.1.queue.cont-buffer"))
def queue_full(ctx: CaseContext) -> None:
    """C with no room in the CONT buffer answers 1; the buffer holds the profile's size."""
    n = ctx.profile.buffer
    if fill_queue(ctx, rule="1.profile.buffer"):
        code(ctx, ctx.link.send("C" + vector(ctx, 1)), ErrorCode.QUEUE_FULL,
             f"vector {n + 1} answers 1", rule="5.code.queue-full")
    ctx.link.send("D")


@case("5.errors.refused-not-executed",
      rules=("4.response.failed-not-executed", "10.1.queue.line-alone"))
def refused_not_executed(ctx: CaseContext) -> None:
    """A command answered with an error is not executed."""
    ctx.link.send("V1000,5")
    ctx.link.send("SW0,1FF")
    r = ctx.link.send("SR0")
    answers(ctx, r, "0,00", "SW0,1FF (out of range) did not write ST0",
            rule="4.response.failed-not-executed")
    setup(ctx, "L" + vector(ctx, 10))
    code(ctx, ctx.link.send("L" + vector(ctx, 20)), ErrorCode.QUEUE_FULL, "L while busy → 1",
         rule="10.1.queue.line-alone")
    finished(ctx, 30)
    r = ctx.link.send("PF")
    ctx.expect(r is not None and r.values[:1] == ["10"], "only the accepted L moved",
               observed=r, expected="0,10,0,0", rule="4.response.failed-not-executed")


@case("5.errors.unknown",
      rules=("5.code.unknown",))
def unknown(ctx: CaseContext) -> None:
    """An unknown command answers 3."""
    for body in ("Z", "E", "XQ"):
        code(ctx, ctx.link.send(body), ErrorCode.UNKNOWN, f"{body} → 3")
