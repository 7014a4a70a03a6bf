"""Section 6: checksums."""

from __future__ import annotations

from conformance.case import CaseContext, case
from conformance.cases._kit import answers, code, setup
from conformance.link.framing import byte_sum


@case("6.checksum.mode-on-off",
      rules=("6.checksum.mode-answers",),
      requires=("%",))
def on_off(ctx: CaseContext) -> None:
    """!0%+ answers 0,5C (already summed); !0%-,CF answers 0."""
    answers(ctx, ctx.link.send("%+", checksum=False), "0,5C", "%+ → 0,5C")
    answers(ctx, ctx.link.send("%-", checksum=True), "0", "%-,CF → 0 without a checksum")


@case("6.checksum.command-summed",
      rules=("6.checksum.sum",),
      tag="M-ex", requires=("%",))
def command_summed(ctx: CaseContext) -> None:
    """The checksum sums every byte from '!' through the comma: !0A100, → 4F."""
    setup(ctx, "%+", checksum=False)
    ctx.expect(byte_sum(b"!0A100,") == 0x4F, "the suite's own sum of the example")
    answers(ctx, ctx.link.send("A100", checksum="4F"), "0,5C", "!0A100,4F is accepted")


@case("6.checksum.bad-sum-rejected",
      rules=("6.checksum.bad-refused", "4.response.failed-not-executed"),
      requires=("%",))
def bad_sum(ctx: CaseContext) -> None:
    """In checksum mode a wrong checksum is not executed and answers 4."""
    setup(ctx, "%+", checksum=False)
    r = ctx.link.send("SW0,0F", checksum="00")
    code(ctx, r, 4, "a wrong checksum → 4", rule="6.checksum.bad-refused")
    ctx.expect(r is not None and bool(r.checksum_ok), "the error carries a checksum",
               observed=r, expected="4,60", rule="6.checksum.bad-refused")
    r = ctx.link.send("SR0")
    ctx.expect(r is not None and r.values[:1] == ["00"], "the refused frame was not executed",
               observed=r, expected="0,00,XX", rule="4.response.failed-not-executed")


@case("6.checksum.missing-sum-rejected",
      rules=("6.checksum.bad-refused",),
      requires=("%",))
def missing(ctx: CaseContext) -> None:
    """In checksum mode a frame without a checksum answers 4."""
    setup(ctx, "%+", checksum=False)
    code(ctx, ctx.link.send("A100", checksum=False), 4, "no checksum → 4")


@case("6.checksum.lower-case-accepted",
      rules=("3.frame.checksum-case",),
      requires=("%",))
def lower(ctx: CaseContext) -> None:
    """Checksum hex digits are accepted in either case."""
    setup(ctx, "%+", checksum=False)
    answers(ctx, ctx.link.send("A100", checksum="4f"), "0,5C", "!0A100,4f is accepted")


@case("6.checksum.responses-summed",
      rules=("6.checksum.response-sum",),
      tag="M", requires=("%",))
def responses(ctx: CaseContext) -> None:
    setup(ctx, "%+", checksum=False)
    for body in ("SR2", "PF", "?", "@"):
        r = ctx.link.send(body)
        ctx.expect(r is not None and r.checksum_ok is True, f"{body}: the response's sum",
                   observed=r, expected="a valid upper-case checksum")


@case("6.checksum.absent-on-gve54",
      rules=("1.profile.gve54-no-checksums", "1.profile.command-set"),
      absent=("%",))
def absent(ctx: CaseContext) -> None:
    """A unit without checksums answers % with 3."""
    code(ctx, ctx.link.send("%+"), 3, "%+ → 3")
