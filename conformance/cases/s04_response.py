"""Spec section 4, Response frame: the cases that check it.

A code (bit 3 is ST6.INTA), values, an optional checksum, CR."""

from __future__ import annotations

from conformance.case.context import CaseContext, case
from conformance.cases._kit import answers, code, halted_with_queue, show
from gve_fixtures.protocol import ErrorCode


@case("4.response.hex-values",
      rules=("4.response.value-format", "3.params.hex-digits"),
      tag="M")
def hex_values(ctx: CaseContext) -> None:
    """Status words and ports are two upper-case hex digits."""
    ctx.link.send("SW2,ab")
    answers(ctx, ctx.link.send("SR2"), "0,AB", "SR2 in upper case after SW2,ab",
            rule="3.params.hex-digits")


@case("4.response.inta-bit",
      rules=("4.response.inta-bit",))
def inta_bit(ctx: CaseContext) -> None:
    """While ST6.INTA = 1 every response carries bit 3 (8..F)"""
    halted_with_queue(ctx)
    for body, value in (("V1000", ErrorCode.OK), ("T99", ErrorCode.RANGE), ("Z", ErrorCode.UNKNOWN),
                        ("SR6", ErrorCode.OK), ("PF", ErrorCode.OK)):
        r = ctx.link.send(body)
        code(ctx, r, value, f"{body} while interrupted", inta=True)


@case("4.response.refused-has-no-values",
      rules=("4.response.failed-no-values",))
def refused(ctx: CaseContext) -> None:
    """A failing command's response carries no values."""
    for body in ("SR9", "ERXY", "PF1"):
        r = ctx.link.send(body)
        ctx.expect(r is not None and r.code and not r.values, f"{body} → code only",
                   observed=show(r), expected="an error code alone")
