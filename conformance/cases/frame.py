"""Sections 2-4: the link, the command frame, the response frame."""

from __future__ import annotations

from conformance.case import CaseContext, case
from conformance.cases._kit import answers, code, index, index_moved, show
from conformance.link.framing import Response, frame
from conformance.link.link import MARGIN
from conformance.motion.tolerance import byte_ns


@case("2.link.other-address-ignored",
      rules=("2.link.addressed-only", "3.frame.other-address-whole", "8.index.uncounted"),
      tag="M", source="M114 1, 9.5; spec 2-3",
      rule="Only the addressed unit answers; a frame for another address is ignored whole")
def other_address(ctx: CaseContext) -> None:
    link = ctx.link
    other = (link.address + 1) % 8
    if other == 7:
        other = (other + 1) % 8
    before = index(ctx)
    link.send("V2000", address=other, answer=False)
    got = link.wait(0.3)
    ctx.expect(got == b"", "no answer to another address", observed=got, expected=b"",
               tag="always")
    index_moved(ctx, before, 0, "the ignored frame did not count in the index",
                rule="8.index.uncounted")


@case("3.frame.noise-before-bang",
      rules=("3.frame.noise-ignored",),
      tag="D", source="spec 3 [D]",
      rule="Bytes before '!' are ignored")
def noise(ctx: CaseContext) -> None:
    ctx.link.send_raw(b"\x00xyz 12\n")
    answers(ctx, ctx.link.send("?"), "0," + ctx.profile.version, "a frame after noise")


@case("3.frame.bang-restarts",
      rules=("3.frame.bang-restarts", "2.link.simplex"),
      tag="D", source="spec 3 [D]",
      rule="A '!' inside an unfinished frame starts a new frame; the old one gets no answer")
def restart(ctx: CaseContext) -> None:
    before = index(ctx)
    ctx.link.send_raw(b"!%dV12" % ctx.link.address)
    index_moved(ctx, before, 0, "only the complete frame is answered; the dropped one not counted",
                rule="3.frame.bang-restarts")
    # an answer here is one to the dropped frame, not a second one to a frame: the
    # manual is silent on a '!' inside a frame
    ctx.expect(ctx.link.wait(0.3) == b"", "no second answer", rule="3.frame.bang-restarts")


@case("3.frame.lf-after-cr",
      rules=("3.frame.lf-ignored", "2.link.simplex"),
      tag="D", source="spec 3 [D]",
      rule="A LF after CR is ignored")
def lf(ctx: CaseContext) -> None:
    before = index(ctx)
    ctx.link.send_raw(b"!%dV1000\r\n" % ctx.link.address)
    r = ctx.link.read_response(1.0)
    answers(ctx, r, "0", "the frame is answered once", rule="3.frame.lf-ignored")
    index_moved(ctx, before, 1, "the LF made no frame", rule="3.frame.lf-ignored")


@case("3.frame.lower-case-unknown",
      rules=("3.frame.upper-case", "5.code.unknown"),
      tag="D", source="spec 3 [D]",
      rule="Command letters are upper case: a lower-case command is unknown (3)")
def lower(ctx: CaseContext) -> None:
    code(ctx, ctx.link.send("v1000"), 3, "v1000 is an unknown command",
         rule="3.frame.upper-case")
    r = ctx.link.send("?")
    ctx.expect(r is not None and r.code == 0, "still answering", observed=show(r),
               expected="0,<version>", rule="3.frame.upper-case")


@case("3.frame.syntax-errors",
      rules=("3.params.decimal", "5.code.syntax"),
      tag="D", source="spec 3 [D]; M84 12.6 code 4",
      rule="A '+', a space, an empty field or a non-digit in a number is a syntax error (4)")
def syntax(ctx: CaseContext) -> None:
    # a wrong count or a letter in a number is the manual's; a sign, a space, an empty
    # field our reading [D]
    for body, rule in (("V+100", "3.params.decimal"), ("V 100", "3.params.decimal"),
                       ("V", "5.code.syntax"), ("V1x", "5.code.syntax"),
                       ("T5,5", "5.code.syntax"), ("L1,,2", "3.params.decimal")):
        code(ctx, ctx.link.send(body), 4, f"{body} → 4", rule=rule)


@case("3.frame.too-long",
      rules=("3.frame.max-length",),
      tag="D", source="spec 3 [D]",
      rule="A frame longer than 96 bytes is a syntax error (4) once its CR arrives")
def too_long(ctx: CaseContext) -> None:
    code(ctx, ctx.link.send("V" + "0" * 100 + "1000"), 4, "a 106-byte frame → 4")


#: a stall every watchdog ends, whatever the time a unit chose for it (the manuals give
#: none: 3.frame.watchdog-time [D]); sent only to a unit that let half a second pass
WATCHDOG_CEILING_S = 5.0


@case("3.frame.watchdog",
      rules=("3.frame.watchdog", "5.code.watchdog", "8.index.uncounted",
             "3.frame.watchdog-time"),
      tag="M", source="M84 12.6 code 2; spec 3 [timing D]",
      rule="A frame left unfinished longer than the watchdog time is dropped and answered 2",
      timing=True)
def watchdog(ctx: CaseContext) -> None:
    before = index(ctx)
    r, rest = _stalled(ctx, 0.5)
    if r is None or r.code != 2:
        code(ctx, r, 2, "a frame stalled 0.5 s is answered 2 (a 100 ms watchdog)",
             rule="3.frame.watchdog-time")
        before = index(ctx)
        r, rest = _stalled(ctx, WATCHDOG_CEILING_S)
    code(ctx, r, 2, "the unfinished frame is answered 2", rule="5.code.watchdog")
    ctx.expect(b"0\r" not in rest, "the rest of the frame is not executed",
               observed=rest, expected="no further answer except an error", tag="always")
    index_moved(ctx, before, 0, "a frame dropped by the watchdog does not count",
                rule="8.index.uncounted")


def _stalled(ctx: CaseContext, seconds: float) -> tuple[Response | None, bytes]:
    """`V1000` with a pause of ``seconds`` after its fourth byte: its answer, and what
    came in the 0.3 s after it."""
    ctx.link.inject("host", "delay", at=4, seconds=seconds)
    r = ctx.link.send("V1000", timeout=seconds + 0.5)
    return r, ctx.link.wait(0.3)


@case("3.frame.lone-bang-silent",
      rules=("3.frame.watchdog-lone-bang",),
      tag="D", source="spec 3 [D]",
      rule="If only '!' arrived before the watchdog time, nothing is answered", timing=True)
def lone_bang(ctx: CaseContext) -> None:
    ctx.link.send_raw(b"!")
    got = ctx.link.wait(0.5)
    ctx.expect(got == b"", "no answer to a lone '!'", observed=got, expected=b"")


@case("4.response.inta-bit",
      rules=("4.response.inta-bit",),
      tag="M", source="M84 12.6",
      rule="While ST6.INTA = 1 every response carries bit 3 (8..F)")
def inta_bit(ctx: CaseContext) -> None:
    from conformance.cases._kit import halted_with_queue
    halted_with_queue(ctx)
    for body, value in (("V1000", 0), ("T99", 5), ("Z", 3), ("SR6", 0), ("PF", 0)):
        r = ctx.link.send(body)
        code(ctx, r, value, f"{body} while interrupted", inta=True)


@case("4.response.hex-values",
      rules=("4.response.value-format", "3.params.hex-digits"),
      tag="M", source="M-ex 12.6; M84 12.5.11",
      rule="Status words and ports are two upper-case hex digits")
def hex_values(ctx: CaseContext) -> None:
    ctx.link.send("SW2,ab")
    answers(ctx, ctx.link.send("SR2"), "0,AB", "SR2 in upper case after SW2,ab",
            rule="3.params.hex-digits")


@case("4.response.refused-has-no-values",
      rules=("4.response.failed-no-values",),
      tag="D", source="spec 4 [D]",
      rule="A failing command's response carries no values")
def refused(ctx: CaseContext) -> None:
    for body in ("SR9", "ERXY", "PF1"):
        r = ctx.link.send(body)
        ctx.expect(r is not None and r.code and not r.values, f"{body} → code only",
                   observed=show(r), expected="an error code alone")


@case("2.link.answers-at-once", rules=("2.link.answer-promptly",))
def at_once(ctx: CaseContext) -> None:
    link = ctx.link
    for body in ("V1000", "PF", "SR6", "?", "Z"):
        r = link.send(body)
        wire = (len(frame(body, link.address, link.checksums)) + (len(r.raw) if r else 0)) \
            * byte_ns(link.baud)
        # a real unit may take the link's margin to process a frame (spec 2: "as soon as
        # possible"; later is a timeout anyway); in virtual time the emulator takes none
        limit = wire + (0 if link.virtual else round(MARGIN * 1e9))
        took = None if r is None else r.received_at - r.sent_at
        ctx.expect(took is not None and took <= limit, f"{body} is answered at once",
                   observed=f"{took} ns", expected=f"at most {limit} ns (the bytes' time"
                   f"{'' if link.virtual else f' and {MARGIN} s'})")
