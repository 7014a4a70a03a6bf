"""Spec section 10.1, Queue, L and C: the cases that check it.

The CONT buffer, stand-alone and continuous vectors."""

from __future__ import annotations

from conformance.case.context import CaseContext, case
from conformance.cases._kit import (
    answers,
    code,
    fill_queue,
    finished,
    measured_case,
    position,
    setup,
    show,
    step_factor,
    vector,
)
from conformance.protocol.wire import is_hex_byte
from gve_fixtures.protocol import ErrorCode, St6

#: the vectors refused for want of room, then sent again until accepted: along Y and Z,
#: where the queue's back-and-forth vectors along X never go
REFUSED_C, REFUSED_L = (0, 3, 0), (0, 0, 5)


# id -> (rules (the first judges the readings), commands it requires, families, scenario)
SCENARIOS: dict[str, tuple[tuple[str, ...], tuple[str, ...], tuple[str, ...], list]] = {
    # modal parameters are captured with each vector when it is accepted (10.1)
    "10.1.measured.captured": (
        ("10.1.queue.captured",), (), (),
        ["A10000", "V1000", "C400,0,0", "V3000", "A1", "C400,0,0", 0.9]),
}


for _id, (_rules, _requires, _families, _scenario) in SCENARIOS.items():
    measured_case(_id, _rules, _requires, _families, _scenario)


@case("10.1.line.refused-while-busy",
      rules=("10.1.queue.line-alone", "5.code.queue-full"))
def l_busy(ctx: CaseContext) -> None:
    """L is accepted only when nothing is queued or running; otherwise 1."""
    setup(ctx, "C" + vector(ctx, 500))
    code(ctx, ctx.link.send("L" + vector(ctx, 10)), ErrorCode.QUEUE_FULL, "L while a C runs → 1",
         rule="10.1.queue.line-alone")
    finished(ctx, 30)
    ctx.expect_equal(position(ctx), [500, 0, 0], "the refused L did not move",
                     rule="10.1.queue.line-alone")


@case("10.1.cont.behind-line", rules=("10.1.queue.c-behind-line",))
def c_behind_l(ctx: CaseContext) -> None:
    """A C sent while an L runs is queued behind it (spec 10.1 [D]; a unit may answer 1
    until the L has ended)."""
    setup(ctx, "L" + vector(ctx, 300))
    code(ctx, ctx.link.send("C" + vector(ctx, 10)), ErrorCode.OK, "C while an L runs → 0",
         rule="10.1.queue.c-behind-line")
    finished(ctx, 30)
    ctx.expect_equal(position(ctx), [310, 0, 0], "the C ran after the L",
                     rule="10.1.queue.c-behind-line")


@case("10.1.line.wait-idiom",
      rules=("10.1.queue.wait-idiom",))
def idiom(ctx: CaseContext) -> None:
    setup(ctx, "L" + vector(ctx, 300))
    code(ctx, ctx.link.send("L" + vector(ctx, 0)), ErrorCode.QUEUE_FULL, "L0,0,0 while moving → 1")
    r = ctx.link.poll("L" + vector(ctx, 0), lambda r: r.code != ErrorCode.QUEUE_FULL, 30)
    code(ctx, r, ErrorCode.OK, "L0,0,0 once idle → 0")
    ctx.expect_equal(position(ctx), [300, 0, 0], "the first L completed")


@case("10.1.queue.executing-counts",
      rules=("10.1.queue.cont-buffer", "10.cmd.flags", "1.profile.buffer",
             "10.3.st6.run-pending"))
def queue_full_flag(ctx: CaseContext) -> None:
    """The CONT buffer's size includes the executing vector; F shows bit 5 when full."""
    if fill_queue(ctx, rule="1.profile.buffer"):
        r = ctx.link.send("F")
        text = r.values[0] if r is not None and r.values else ""
        flags = int(text, 16) if is_hex_byte(text, either_case=True) else None
        full = St6.INTA | St6.RUN | St6.INTCOM | St6.QUEUE_FULL
        ctx.expect(flags is not None and flags | St6.RUN == full,
                   "F = INTA + RUN + INTCOM + full", observed=show(r), expected="8,F0",
                   rule="10.cmd.flags")
        # RUN for vectors queued behind a halt is our reading: the manual's RUN is "je
        # zpracováván vektor" (a vector is being processed)
        if flags is not None and flags | St6.RUN == full and not flags & St6.RUN:
            ctx.expect(False, "RUN = 1: vectors wait in the queue behind the halt",
                       observed=show(r), expected="8,F0", rule="10.3.st6.run-pending")
    ctx.link.send("D")


@case("10.1.queue.refused-leaves-queue",
      rules=("5.code.queue-full", "10.1.queue.cont-buffer", "4.response.failed-not-executed"))
def refused_vector(ctx: CaseContext) -> None:
    link = ctx.link
    start = position(ctx)
    ctx.require(start is not None, "PF did not answer with positions")
    if not fill_queue(ctx, rule="10.1.queue.cont-buffer"):   # H, then ±1 along X
        return
    before = link.send("F")
    code(ctx, link.send("C" + vector(ctx, *REFUSED_C)), ErrorCode.QUEUE_FULL,
         "C into a full queue → 1 (9)",
         inta=True, rule="5.code.queue-full")
    code(ctx, link.send("L" + vector(ctx, *REFUSED_L)), ErrorCode.QUEUE_FULL,
         "L while vectors wait → 1 (9)",
         inta=True, rule="5.code.queue-full")
    after = link.send("F")
    ctx.expect(after is not None and before is not None and after.raw == before.raw,
               "F is as before the refusals (the queue still full, no more)",
               observed=show(after), expected=show(before), rule="10.1.queue.cont-buffer")
    answers(ctx, link.send("G"), "0", "G runs the queue", rule="10.1.queue.cont-buffer")
    # the host's retry: each refused vector is sent again until the unit takes it
    for kind, d in (("C", REFUSED_C), ("L", REFUSED_L)):
        r = link.poll(kind + vector(ctx, *d), lambda r: r.code != ErrorCode.QUEUE_FULL, 120)
        code(ctx, r, ErrorCode.OK,
             f"{kind}{vector(ctx, *d)} sent again is taken once there is room",
             rule="5.code.queue-full")
    r = finished(ctx, 30, lambda r: r.code != ErrorCode.QUEUE_FULL)
    ctx.require(r is not None and r.ok, "the queue did not run out within 30 s")
    drift = sum(1 if i % 2 == 0 else -1 for i in range(ctx.profile.buffer))
    moved = [drift, REFUSED_C[1], REFUSED_L[2]]
    expected = None if start is None else [s + m * step_factor(ctx)
                                           for s, m in zip(start, moved, strict=True)]
    ctx.expect_equal(position(ctx), expected,
                     "every queued vector ran once, and each refused one only once taken",
                     rule="4.response.failed-not-executed")
