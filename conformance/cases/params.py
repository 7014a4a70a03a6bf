"""Sections 1 and 3: parameters — the ranges of every modal parameter per profile, the
axes a vector takes, long decimals, hexadecimal fields, syntax before range, commands
that take no parameters, the bounded frame buffer, the output port."""

from __future__ import annotations

from conformance.case import CaseContext, case
from conformance.cases._kit import answers, code, setup, show

# parameter -> (frame template, the rule its range belongs to on GVE54 / on GVE84, GVE114)
RANGES = {
    "V": ("V{}", "1.profile.v-b-range-gve54", "1.profile.v-b-range"),
    "B": ("B{}", "1.profile.v-b-range-gve54", "1.profile.v-b-range"),
    "$": ("${}", "1.profile.dollar-range", "1.profile.dollar-range"),
    "T": ("T{}", "10.cmd.modal", "10.cmd.modal"),
    "A": ("A{}", "10.cmd.accel-range", "10.cmd.accel-range"),
    "XM": ("XM{}", None, "10.cmd.override"),
    "VL": ("VL{},{},{}", None, "10.cmd.axis-limits"),
}


@case("1.profile.parameter-ranges",
      rules=("1.profile.v-b-range", "1.profile.v-b-range-gve54", "1.profile.dollar-range",
             "10.cmd.modal", "10.cmd.accel-range", "10.cmd.override", "10.cmd.axis-limits",
             "10.cmd.axis-limits-clamped", "5.code.range"))
def ranges(ctx: CaseContext) -> None:
    p = ctx.profile
    for name, (template, rule54, rule) in RANGES.items():
        rule = rule54 if p.family == "GVE54" else rule
        if rule is None or name not in p.ranges:
            continue
        lo, hi = p.ranges[name].lo, p.ranges[name].hi
        for value, want in ((lo - 1, 5), (lo, 0), (hi, 0), (hi + 1, 5)):
            body = template.format(*[value] * template.count("{}"))
            code(ctx, ctx.link.send(body), want, f"{body} → {want}", rule=rule)
    if "VL" in p.commands and p.ranges["VL"].hi > p.max_rate:
        hi = p.ranges["VL"].hi
        code(ctx, ctx.link.send(f"VL{hi},{hi},{hi}"), 0,
             f"VL above the variant's {p.max_rate} is accepted (clamped)",
             rule="10.cmd.axis-limits-clamped")
    else:
        code(ctx, ctx.link.send("VL1000,1000,1000" if "VL" in p.commands else "V1000"), 0,
             "a rate in pulses/s within the variant's maximum is accepted as it is",
             rule="10.cmd.axis-limits-clamped" if "VL" in p.commands else "10.cmd.modal")


@case("1.profile.axes.count", rules=("1.profile.axes",))
def axes(ctx: CaseContext) -> None:
    four = len(ctx.profile.axes) == 4
    setup(ctx, "H", expect="8")              # vectors wait in the queue while INTA = 1
    code(ctx, ctx.link.send("C0,0,0,1"), 0 if four else 4,
         f"a fourth component: {'the A axis' if four else 'no such axis'}", inta=True)
    code(ctx, ctx.link.send("C1,0"), 4, "two components are too few", inta=True)
    setup(ctx, "D")


# on a real unit the guard sends no vector beyond --max-travel: COULD-NOT-TEST there
@case("1.profile.vector-range.limits", rules=("1.profile.vector-range",))
def vector_range(ctx: CaseContext) -> None:
    top = ctx.profile.vector_range
    setup(ctx, "H", expect="8")              # vectors wait in the queue while INTA = 1
    code(ctx, ctx.link.send(f"C{top},0,0"), 0, f"a component of {top} is in range", inta=True)
    code(ctx, ctx.link.send(f"C0,{-top},0"), 0, f"and of {-top}", inta=True)
    code(ctx, ctx.link.send(f"C{top + 1},0,0"), 5, f"{top + 1} is out of range", inta=True)
    setup(ctx, "D")


def no_envelope(ctx: CaseContext) -> bool:
    """Whether the target takes the spec's examples with a vector of 9999999999999 steps:
    the emulator only (the guard never sends a vector it cannot bound to a real unit)."""
    return not ctx.target.real


@case("3.params.long-decimals", rules=("3.params.long-decimal",))
def long_decimals(ctx: CaseContext) -> None:
    answers(ctx, ctx.link.send("T0000000000005"), "0", "T0000000000005: five, in range")
    answers(ctx, ctx.link.send("$9999999999999"), "5", "$9999999999999: out of range")
    if no_envelope(ctx):
        answers(ctx, ctx.link.send("L9999999999999,0,0"), "5",
                "L9999999999999,0,0: out of range")
    answers(ctx, ctx.link.send("V" + "0" * 30 + "1000"), "0", "thirty leading zeros")


@case("3.params.hex-fields", rules=("3.params.hex-fields", "3.params.hex-digits"))
def hex_fields(ctx: CaseContext) -> None:
    setup(ctx, "SW3,10")
    answers(ctx, ctx.link.send("SR3"), "0,10", "SW's value is hex: 10 is sixteen",
            rule="3.params.hex-fields")
    # the EEPROM holds the owner's bytes: the same address written three ways reads alike
    forms = {body: ctx.link.send(body) for body in ("ER0D", "ERD", "ER00D")}
    ok = all(r is not None and r.code == 0 and len(r.values) == 1 for r in forms.values())
    read = {r.hex() for r in forms.values()} if ok else set()
    ctx.expect(ok and len(read) == 1, "ER's address is hex: ER0D, ERD and ER00D read one byte",
               observed=", ".join(f"{b} → {show(r)}" for b, r in forms.items()),
               expected="0,XX three times", rule="3.params.hex-fields")
    for body in ("ER0G", "ERG"):
        answers(ctx, ctx.link.send(body), "4", f"{body}: not a hex address → 4",
                rule="3.params.hex-fields")
    answers(ctx, ctx.link.send("SW3,001"), "0", "SW3,001: three digits, in range",
            rule="3.params.hex-digits")
    answers(ctx, ctx.link.send("SR3"), "0,01", "and the value is 01", rule="3.params.hex-digits")
    answers(ctx, ctx.link.send("SW3,c"), "0", "one lower-case digit", rule="3.params.hex-digits")
    answers(ctx, ctx.link.send("SW2,FFF"), "5", "SW2,FFF: out of range",
            rule="3.params.hex-digits")


@case("3.params.syntax-first", rules=("3.params.syntax-before-range",))
def syntax_first(ctx: CaseContext) -> None:
    answers(ctx, ctx.link.send("SW9,+5"), "4",
            "SW9,+5: an out-of-range field and a malformed one: syntax wins")
    if no_envelope(ctx):
        answers(ctx, ctx.link.send("L9999999999999,+5,0"), "4", "L9999999999999,+5,0 → 4")
    if "VL" in ctx.profile.commands:
        answers(ctx, ctx.link.send("VL2147483648,5000,+5"), "4", "VL2147483648,5000,+5 → 4")
    answers(ctx, ctx.link.send("T99,1"), "4", "one field too many, out of range as well")


@case("3.params.none-expected.given", rules=("3.params.none-expected",))
def none_expected(ctx: CaseContext) -> None:
    for body in ("@1", ">1", "?5", "G0", "H1"):
        answers(ctx, ctx.link.send(body), "4", f"{body}: a parameter where none is taken")


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


@case("10.cmd.output.port", rig=True, rules=("10.cmd.output",))
def output(ctx: CaseContext) -> None:
    link = ctx.link
    answers(ctx, link.send("O0,FB"), "0", "O0,FB: coolant on")
    seen = link.rig.outputs()                # read once: a technician may be the one asked
    ctx.expect(seen == 0xFB, "the outputs are FB", observed=seen, expected=0xFB)
    answers(ctx, link.send("O1,FF"), "5", "O1,FF: port 1 does not exist")
    answers(ctx, link.send("O"), "4", "O without parameters")
    seen = link.rig.outputs()
    ctx.expect(seen == 0xFB, "the refused frames changed nothing", observed=seen,
               expected=0xFB)
    answers(ctx, link.send("O0,FF"), "0", "O0,FF: all off")


