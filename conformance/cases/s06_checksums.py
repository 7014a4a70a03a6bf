"""Spec section 6, Checksums: the cases that check it.

`%+` and `%-`: the byte sum modulo 256 on frames and responses."""

from __future__ import annotations

from conformance.case.context import CaseContext, case
from conformance.cases._kit import answers, code, index, index_moved, setup, show
from conformance.link.framing import byte_sum
from gve_fixtures.protocol import ErrorCode


def _gve114(p) -> bool:
    return p.family == "GVE114"


@case("6.checksum.absent-on-gve54",
      rules=("1.profile.gve54-no-checksums", "1.profile.command-set"),
      absent=("%",))
def absent(ctx: CaseContext) -> None:
    """A unit without checksums answers % with 3."""
    code(ctx, ctx.link.send("%+"), ErrorCode.UNKNOWN, "%+ → 3",
         rule="1.profile.gve54-no-checksums")


@case("6.checksum.address-7-shares", requires=("%",), applies=_gve114,
      rules=("6.checksum.spindle-shares",))
def spindle_shares(ctx: CaseContext) -> None:
    link = ctx.link
    before = index(ctx)                      # a used unit's index is wherever it is
    ctx.require(before is not None, "@ at address 0 gave no index")
    setup(ctx, "%+", checksum=False)
    code(ctx, link.send("?", address=7, checksum=False), ErrorCode.SYNTAX,
         "address 7 is in checksum mode too: a frame without one → 4")
    r = link.send("@", address=7)
    want = (before + 1) % 256
    ctx.expect(r is not None and r.checksum_ok is True and r.ok
               and link.index_value(r) == want,
               "address 7 counts the index of address 0 (%+ counted, the unsummed ? not)",
               observed=show(r), expected=f"0,{want},XX")
    setup(ctx, "V1000")
    index_moved(ctx, before, 2, "a frame at address 0 moves it", address=7)


@case("6.checksum.bad-sum-rejected",
      rules=("6.checksum.bad-refused", "4.response.failed-not-executed"),
      requires=("%",))
def bad_sum(ctx: CaseContext) -> None:
    """In checksum mode a wrong checksum is not executed and answers 4."""
    setup(ctx, "%+", checksum=False)
    r = ctx.link.send("SW0,0F", checksum="00")
    code(ctx, r, ErrorCode.SYNTAX, "a wrong checksum → 4", rule="6.checksum.bad-refused")
    ctx.expect(r is not None and bool(r.checksum_ok), "the error carries a checksum",
               observed=r, expected="4,60", rule="6.checksum.bad-refused")
    r = ctx.link.send("SR0")
    ctx.expect(r is not None and r.values[:1] == ["00"], "the refused frame was not executed",
               observed=r, expected="0,00,XX", rule="4.response.failed-not-executed")


@case("6.checksum.command-summed",
      rules=("6.checksum.sum",),
      tag="M-ex", requires=("%",))
def command_summed(ctx: CaseContext) -> None:
    """The checksum sums every byte from '!' through the comma: !0A100, → 4F."""
    setup(ctx, "%+", checksum=False)
    ctx.expect(byte_sum(b"!0A100,") == 0x4F, "the suite's own sum of the example")
    answers(ctx, ctx.link.send("A100", checksum="4F"), "0,5C", "!0A100,4F is accepted")


@case("6.checksum.lower-case-accepted",
      rules=("3.frame.checksum-case",),
      requires=("%",))
def lower(ctx: CaseContext) -> None:
    """Checksum hex digits are accepted in either case."""
    setup(ctx, "%+", checksum=False)
    answers(ctx, ctx.link.send("A100", checksum="4f"), "0,5C", "!0A100,4f is accepted")


@case("6.checksum.missing-sum-rejected",
      rules=("6.checksum.bad-refused",),
      requires=("%",))
def missing(ctx: CaseContext) -> None:
    """In checksum mode a frame without a checksum answers 4."""
    setup(ctx, "%+", checksum=False)
    code(ctx, ctx.link.send("A100", checksum=False), ErrorCode.SYNTAX, "no checksum → 4")


@case("6.checksum.mode-on-off",
      rules=("6.checksum.mode-answers",),
      requires=("%",))
def on_off(ctx: CaseContext) -> None:
    """!0%+ answers 0,5C (already summed); !0%-,CF answers 0."""
    answers(ctx, ctx.link.send("%+", checksum=False), "0,5C", "%+ → 0,5C")
    answers(ctx, ctx.link.send("%-", checksum=True), "0", "%-,CF → 0 without a checksum")


@case("6.checksum.responses-summed",
      rules=("6.checksum.response-sum",),
      tag="M", requires=("%",))
def responses(ctx: CaseContext) -> None:
    setup(ctx, "%+", checksum=False)
    for body in ("SR2", "PF", "?", "@"):
        r = ctx.link.send(body)
        ctx.expect(r is not None and r.checksum_ok is True, f"{body}: the response's sum",
                   observed=r, expected="a valid upper-case checksum")
