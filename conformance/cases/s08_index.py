"""Spec section 8, Index `@` and repeat `>`: the cases that check it.

`@` counts the frames a unit received, `>` repeats the last one and its answer: the host's
way to recover a lost answer."""

from __future__ import annotations

from conformance.case.context import CaseContext, case
from conformance.cases._kit import (
    answers,
    finished,
    fresh_reset,
    index,
    index_moved,
    position,
    setup,
    vector,
)
from conformance.link.framing import byte_sum


@case("8.index.counts-every-frame",
      rules=("8.index.counts", "8.index.refused-counted"))
def counts(ctx: CaseContext) -> None:
    """Every complete frame advances the index by one, refused ones too (that one our
    reading: a unit may count only what it took)."""
    link = ctx.link
    before = index(ctx)
    link.send("V1000")
    index_moved(ctx, before, 1, "a frame taken is counted", rule="8.index.counts")
    before = index(ctx)
    link.send("T99")          # refused: 5
    link.send("Z")            # refused: 3
    index_moved(ctx, before, 2, "two frames refused, counted", rule="8.index.refused-counted")


@case("8.index.modulo-256",
      rules=("8.index.counts",))
def modulo(ctx: CaseContext) -> None:
    """The index counts modulo 256."""
    before = index(ctx)
    for _ in range(258):
        ctx.link.send("F")
    index_moved(ctx, before, 258, "258 frames later the index moved by 2 (mod 256)")


@case("8.index.queries-not-counted", rules=("8.index.queries-uncounted",))
def queries(ctx: CaseContext) -> None:
    link = ctx.link
    before = index(ctx)
    link.send("V1000")
    link.send("@")
    link.send(">", lines=2)
    index_moved(ctx, before, 1, "only V1000 counted", queries=True)


@case("8.recovery.lost-response",
      rules=("8.index.counts", "8.repeat.answer", "8.repeat.remembered"))
def lost_response(ctx: CaseContext) -> None:
    """A lost response is recovered with @ and > without executing the vector twice."""
    link = ctx.link
    before = index(ctx)
    link.inject("unit", "drop")
    lost = link.send("L" + vector(ctx, 9))
    ctx.require(lost is None, "the injected loss did not happen")
    index_moved(ctx, before, 1, "the index shows the command arrived", rule="8.index.counts")
    r = link.send(">", lines=2)
    # > showing the @ just sent: that @ is never remembered is our reading [D]
    shows_index = r is not None and r.lines[:1] == [f"!{link.address}@".encode()]
    answers(ctx, r, f"!{link.address}L{vector(ctx, 9)}\r0", "> shows the lost answer",
            rule="8.repeat.remembered" if shows_index else "8.repeat.answer")
    finished(ctx, 30)
    ctx.expect_equal(position(ctx), [9, 0, 0], "executed exactly once", rule="8.index.counts")


@case("8.repeat.last-frame-and-answer",
      rules=("8.repeat.answer", "8.repeat.remembered"))
def repeat(ctx: CaseContext) -> None:
    """> answers the last frame as received, then the response it got."""
    link = ctx.link
    link.send("T99")
    r = link.send(">", lines=2)
    expected = f"!{link.address}T99\r5"
    answers(ctx, r, expected, "> repeats the refused frame and its answer",
            rule="8.repeat.answer")


@case("8.repeat.no-history",
      rules=("8.repeat.answer",))
def no_history(ctx: CaseContext) -> None:
    """With no history since reset, > answers a single line 0."""
    fresh_reset(ctx)
    answers(ctx, ctx.link.send(">"), "0", "> right after reset")


@case("8.repeat.not-reexecuted", rules=("8.repeat.no-reexecute",))
def not_again(ctx: CaseContext) -> None:
    link = ctx.link
    start = position(ctx)
    ctx.require(start is not None, "PF answered")
    setup(ctx, "L" + vector(ctx, 7))
    before = link.send("@")
    link.send(">", lines=2)
    after = link.send("@")
    ctx.expect(before is not None and after is not None and before.values == after.values,
               "> added no frame to the index", observed=after, expected=before, tag="D")
    finished(ctx, 30)
    here = position(ctx)
    want = [start[0] + 7, start[1], start[2]]
    ctx.expect(here == want, "the vector ran once", observed=here, expected=want, tag="always")


@case("8.repeat.queries-forgotten", requires=("%",), rules=("8.repeat.remembered",))
def queries_forgotten(ctx: CaseContext) -> None:
    link = ctx.link
    setup(ctx, "%+", checksum=False)
    setup(ctx, "V1000")
    link.send("@", checksum="00")                  # a bad checksum: answered 4, not kept
    link.send(">", checksum="00", lines=1)
    r = link.send(">", lines=2)
    ctx.expect(r is not None and r.lines[:1] == [f"!{link.address}V1000,%02X".encode()
                                                 % byte_sum(f"!{link.address}V1000,".encode())],
               "> still shows V1000: @ and > are never remembered, even refused",
               observed=r, expected=f"!{link.address}V1000,XX then 0,5C")
