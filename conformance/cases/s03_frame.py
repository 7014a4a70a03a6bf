"""Spec section 3, Command frame: the cases that check it.

`!`, an address 0..7, a body, an optional checksum, CR: how a unit frames what it receives
and reads its parameters (syntax is checked before range)."""

from __future__ import annotations

from conformance.case.context import CaseContext, case
from conformance.cases._kit import answers, code, index, index_moved, setup, show
from conformance.link.account import Spent
from conformance.link.framing import Response
from gve_fixtures.protocol import ErrorCode

#: a stall every watchdog ends, whatever the time a unit chose for it (the manuals give
#: none: 3.frame.watchdog-time [D]); sent only to a unit that let half a second pass
WATCHDOG_CEILING_S = 5.0


def _stalled(ctx: CaseContext, seconds: float) -> tuple[Response | None, bytes]:
    """`V1000` with a pause of ``seconds`` after its fourth byte: its answer, and what
    came in the 0.3 s after it."""
    ctx.link.inject("host", "delay", at=4, seconds=seconds)
    r = ctx.link.send("V1000", timeout=seconds + 0.5)
    return r, ctx.link.wait(0.3)


def no_envelope(ctx: CaseContext) -> bool:
    """Whether the target takes the spec's examples with a vector of 9999999999999 steps:
    the emulator only (the guard never sends a vector it cannot bound to a real unit)."""
    return not ctx.target.real


@case("3.frame.bang-restarts",
      rules=("3.frame.bang-restarts", "2.link.simplex"))
def restart(ctx: CaseContext) -> None:
    before = index(ctx)
    ctx.link.send_raw(b"!%dV12" % ctx.link.address)
    index_moved(ctx, before, 0, "only the complete frame is answered; the dropped one not counted",
                rule="3.frame.bang-restarts")
    # an answer here is one to the dropped frame, not a second one to a frame: the
    # manual is silent on a '!' inside a frame
    ctx.expect(ctx.link.wait(0.3) == b"", "no second answer", rule="3.frame.bang-restarts")


@case("3.frame.bounded-buffer.overflow", rules=("3.frame.bounded-buffer", "3.frame.max-length"))
def overflow(ctx: CaseContext) -> None:
    link = ctx.link
    link.send_raw(b"!%dV" % link.address + b"1" * 5000 + b"\r")
    r = link.read_response(2.0)
    answers(ctx, r, "4", "a 5000-byte frame is answered 4 once its CR arrives",
            rule="3.frame.max-length")
    extra = link.wait(0.3)
    ctx.expect(extra == b"", "and only once", observed=extra, expected=b"",
               rule="3.frame.bounded-buffer")
    answers(ctx, link.send("?"), "0," + ctx.profile.version, "the next frame is answered",
            rule="3.frame.bounded-buffer")


@case("3.frame.lf-after-cr",
      rules=("3.frame.lf-ignored", "2.link.simplex"))
def lf(ctx: CaseContext) -> None:
    before = index(ctx)
    ctx.link.send_raw(b"!%dV1000\r\n" % ctx.link.address)
    r = ctx.link.read_response(1.0)
    answers(ctx, r, "0", "the frame is answered once", rule="3.frame.lf-ignored")
    index_moved(ctx, before, 1, "the LF made no frame", rule="3.frame.lf-ignored")


@case("3.frame.lone-bang-silent",
      rules=("3.frame.watchdog-lone-bang",),
      timing=True)
def lone_bang(ctx: CaseContext) -> None:
    """If only '!' arrived before the watchdog time, nothing is answered."""
    ctx.link.send_raw(b"!")
    # the watchdog's time as a unit takes it (M84 12.6, 100 ms), and a margin
    got = ctx.link.wait(0.5, Spent.MANUAL)
    ctx.expect(got == b"", "no answer to a lone '!'", observed=got, expected=b"")


@case("3.frame.lower-case-unknown",
      rules=("3.frame.upper-case", "5.code.unknown"))
def lower(ctx: CaseContext) -> None:
    """Command letters are upper case: a lower-case command is unknown (3)"""
    code(ctx, ctx.link.send("v1000"), ErrorCode.UNKNOWN, "v1000 is an unknown command",
         rule="3.frame.upper-case")
    r = ctx.link.send("?")
    ctx.expect(r is not None and r.ok, "still answering", observed=show(r),
               expected="0,<version>", rule="3.frame.upper-case")


@case("3.frame.noise-before-bang",
      rules=("3.frame.noise-ignored",))
def noise(ctx: CaseContext) -> None:
    ctx.link.send_raw(b"\x00xyz 12\n")
    answers(ctx, ctx.link.send("?"), "0," + ctx.profile.version, "a frame after noise")


@case("3.frame.syntax-errors",
      rules=("3.params.decimal", "5.code.syntax"))
def syntax(ctx: CaseContext) -> None:
    # a wrong count or a letter in a number is the manual's; a sign, a space, an empty
    # field our reading [D]
    """A '+', a space, an empty field or a non-digit in a number is a syntax error (4)"""
    for body, rule in (("V+100", "3.params.decimal"), ("V 100", "3.params.decimal"),
                       ("V", "5.code.syntax"), ("V1x", "5.code.syntax"),
                       ("T5,5", "5.code.syntax"), ("L1,,2", "3.params.decimal")):
        code(ctx, ctx.link.send(body), ErrorCode.SYNTAX, f"{body} → 4", rule=rule)


@case("3.frame.too-long",
      rules=("3.frame.max-length",))
def too_long(ctx: CaseContext) -> None:
    code(ctx, ctx.link.send("V" + "0" * 100 + "1000"), ErrorCode.SYNTAX, "a 106-byte frame → 4")


@case("3.frame.watchdog",
      rules=("3.frame.watchdog", "5.code.watchdog", "8.index.uncounted",
             "3.frame.watchdog-time"),
      timing=True)
def watchdog(ctx: CaseContext) -> None:
    """A frame left unfinished longer than the watchdog time is dropped and answered 2."""
    before = index(ctx)
    r, rest = _stalled(ctx, 0.5)
    if r is None or r.code != ErrorCode.WATCHDOG:
        code(ctx, r, ErrorCode.WATCHDOG, "a frame stalled 0.5 s is answered 2 (a 100 ms watchdog)",
             rule="3.frame.watchdog-time")
        before = index(ctx)
        r, rest = _stalled(ctx, WATCHDOG_CEILING_S)
    code(ctx, r, ErrorCode.WATCHDOG, "the unfinished frame is answered 2", rule="5.code.watchdog")
    ctx.expect(b"0\r" not in rest, "the rest of the frame is not executed",
               observed=rest, expected="no further answer except an error",
               rule="3.frame.watchdog")
    index_moved(ctx, before, 0, "a frame dropped by the watchdog does not count",
                rule="8.index.uncounted")


@case("3.params.float-values", destructive=True, requires=("EFW",),
      rules=("3.params.float-syntax", "3.params.word-values-decimal"))
def floats(ctx: CaseContext) -> None:
    link = ctx.link
    for body, want in (("EFW44,1e+3", "0"), ("EFW44,-2.5E-1", "0"), ("EFW44,+1", "4"),
                       ("EFW44,1.", "4"), ("EFW44,1e39", "5"), ("EFW44,0x10", "4")):
        answers(ctx, link.send(body), want, f"{body} → {want}", rule="3.params.float-syntax")
    answers(ctx, link.send("EFR44"), "0,-0.25", "the last accepted value",
            rule="3.params.float-syntax")
    answers(ctx, link.send("EUW48,10"), "0", "EUW's value is decimal",
            rule="3.params.word-values-decimal")
    answers(ctx, link.send("ER48"), "0,0A", "ten, not sixteen", rule="3.params.word-values-decimal")


@case("3.params.hex-fields", rules=("3.params.hex-fields", "3.params.hex-digits"))
def hex_fields(ctx: CaseContext) -> None:
    setup(ctx, "SW3,10")
    answers(ctx, ctx.link.send("SR3"), "0,10", "SW's value is hex: 10 is sixteen",
            rule="3.params.hex-fields")
    # the EEPROM holds the owner's bytes: the same address written three ways reads alike.
    # The manuals write the address 00..FF: its two digits are the manual's, one or three
    # digits the project's decision
    forms = {body: ctx.link.send(body) for body in ("ER0D", "ERD", "ER00D")}
    first = forms["ER0D"]
    ctx.expect(first is not None and first.ok and len(first.values) == 1,
               "ER's address is hex: ER0D reads one byte", observed=show(first),
               expected="0,XX", rule="3.params.hex-fields")
    ok = all(r is not None and r.ok and len(r.values) == 1 for r in forms.values())
    read = {r.hex() for r in forms.values()} if ok else set()
    ctx.expect(ok and len(read) == 1, "ERD and ER00D read the byte ER0D reads",
               observed=", ".join(f"{b} → {show(r)}" for b, r in forms.items()),
               expected="0,XX three times", rule="3.params.hex-digits")
    for body in ("ER0G", "ERG"):
        answers(ctx, ctx.link.send(body), "4", f"{body}: not a hex address → 4",
                rule="3.params.hex-fields")
    answers(ctx, ctx.link.send("SW3,001"), "0", "SW3,001: three digits, in range",
            rule="3.params.hex-digits")
    answers(ctx, ctx.link.send("SR3"), "0,01", "and the value is 01", rule="3.params.hex-digits")
    answers(ctx, ctx.link.send("SW3,c"), "0", "one lower-case digit", rule="3.params.hex-digits")
    answers(ctx, ctx.link.send("SW2,FFF"), "5", "SW2,FFF: out of range",
            rule="3.params.hex-digits")


@case("3.params.long-decimals", rules=("3.params.long-decimal",))
def long_decimals(ctx: CaseContext) -> None:
    answers(ctx, ctx.link.send("T0000000000005"), "0", "T0000000000005: five, in range")
    answers(ctx, ctx.link.send("$9999999999999"), "5", "$9999999999999: out of range")
    if no_envelope(ctx):
        answers(ctx, ctx.link.send("L9999999999999,0,0"), "5",
                "L9999999999999,0,0: out of range")
    answers(ctx, ctx.link.send("V" + "0" * 30 + "1000"), "0", "thirty leading zeros")


@case("3.params.none-expected.given", rules=("3.params.none-expected",))
def none_expected(ctx: CaseContext) -> None:
    for body in ("@1", ">1", "?5", "G0", "H1"):
        answers(ctx, ctx.link.send(body), "4", f"{body}: a parameter where none is taken")


@case("3.params.syntax-first", rules=("3.params.syntax-before-range",))
def syntax_first(ctx: CaseContext) -> None:
    answers(ctx, ctx.link.send("SW9,+5"), "4",
            "SW9,+5: an out-of-range field and a malformed one: syntax wins")
    if no_envelope(ctx):
        answers(ctx, ctx.link.send("L9999999999999,+5,0"), "4", "L9999999999999,+5,0 → 4")
    if "VL" in ctx.profile.commands:
        answers(ctx, ctx.link.send("VL2147483648,5000,+5"), "4", "VL2147483648,5000,+5 → 4")
    answers(ctx, ctx.link.send("T99,1"), "4", "one field too many, out of range as well")
