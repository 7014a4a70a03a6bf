"""Spec section 1, Units (profiles): the cases that check it.

What distinguishes the GVE54, the GVE84 and the GVE114 and their variants. A profile
(`fixtures/profiles/*.toml`) is this table as data."""

from __future__ import annotations

from conformance.case.context import CaseContext, case
from conformance.cases._kit import answers, code, finished, position, setup, show
from conformance.protocol.catalogue import commands
from gve_fixtures.protocol import ErrorCode
from gve_fixtures.rules import load_rules

#: what a range refusal of a modal parameter breaks where the catalogue names no rule of
#: its own (its `rules`)
RANGE_RULES = {"XM": "10.cmd.override"}


def _ranged(profile) -> list[tuple[str, str, str]]:
    """Every modal command of the catalogue the profile has whose parameter is one of the
    profile's [rates] ranges: (command, frame template, the rule a refusal breaks)."""
    out = []
    for name, c in commands().items():
        if not c.modal or len(c.fields) != 1 or name not in profile.commands:
            continue
        key = c.fields[0].range
        if not isinstance(key, str) or key not in profile.ranges:
            continue
        rules = [r for r in c.rules if _applies(r, profile)]
        count = len(profile.axes) if c.repeat == "axes" else 1
        out.append((key, name + ",".join(["{}"] * count),
                    rules[0] if rules else RANGE_RULES.get(name, "5.code.range")))
    order = list(profile.ranges)               # in the order the profile lists its ranges
    return sorted(out, key=lambda r: order.index(r[0]))


def _past_top(profile, name: str, rule: str) -> str:
    """The rule a refusal just above a range's top breaks. M114 writes VL's range as
    10 - 100000 in a garbled line ("v tis. pulsů/s osy Y") beside V's same range, which
    "záleží na interpolační rychlosti konkrétní jednotky": a reader may take VL's top as
    the variant's rate too, so above 100000 on a faster variant it is the [D] reading."""
    if name == "VL" and profile.max_rate > profile.ranges[name].hi:
        return "10.cmd.axis-limits-clamped"
    return rule


def _applies(rule: str, profile) -> bool:
    r = load_rules()[rule]
    return not r.profiles or profile.family in r.profiles or profile.name in r.profiles


@case("1.profile.axes.count", rules=("1.profile.axes", "10.cmd.vector-components"))
def axes(ctx: CaseContext) -> None:
    """A fourth component is the GVE114's A axis and no axis elsewhere; two components
    (as the manuals' own `!0L1000,100`) are taken as X, Y and zeros, or refused."""
    link = ctx.link
    four = len(ctx.profile.axes) == 4
    start = position(ctx)
    ctx.require(start is not None, "PF did not answer with positions")
    setup(ctx, "H", expect="8")              # vectors wait in the queue while INTA = 1
    code(ctx, link.send("C0,0,0,1"), ErrorCode.OK if four else ErrorCode.SYNTAX,
         f"a fourth component: {'the A axis' if four else 'no such axis'}", inta=True,
         rule="1.profile.axes")
    fewer = "10.cmd.vector-components"
    r = link.send("C1,0")
    ctx.expect(r is not None and r.inta and r.code in (ErrorCode.OK, ErrorCode.SYNTAX),
               "two components: taken with the rest 0, or refused as a wrong count",
               observed=show(r), expected="8 or C", rule=fewer)
    taken = r is not None and r.code == ErrorCode.OK
    # with nothing queued G may answer 6, "nothing to start" (spec 5: both readings)
    setup(ctx, "G", expect="0" if four or taken else ("0", "6"))
    finished(ctx, 30)
    want = [start[0] + taken, start[1], start[2]]
    ctx.expect_equal(position(ctx), want, f"and X moved {int(taken)} step, Y and Z none",
                     rule=fewer)


@case("1.profile.interrupt-inputs.wired", rig=True,
      rules=("1.profile.interrupt-inputs", "1.profile.interrupt-inputs-gve114",
             "10.3.status.meaning"))
def wired(ctx: CaseContext) -> None:
    p = ctx.profile
    rule = "1.profile.interrupt-inputs" + ("-gve114" if p.family == "GVE114" else "")
    for port, enable, cause, mask in ((1, 0, 4, p.low_mask), (2, 1, 5, p.high_mask)):
        for bit in range(8):
            link = ctx.fresh_link()
            r = link.send("SW%d,%02X" % (enable, 1 << bit))
            ctx.require(r is not None and r.ok, f"SW{enable} answered {show(r)}")
            # grounded once enabled: an interrupt whether inputs are level- or
            # edge-triggered (level is our reading [D])
            link.rig.set_input(port, 0xFF ^ (1 << bit))
            r = link.send(f"SR{cause}")
            ctx.require(r is not None and r.ok, f"SR{cause} answered {show(r)}")
            wired = bool(mask >> bit & 1)
            ctx.expect(r.inta == wired, f"IN{bit} of port I{port} "
                       f"{'interrupts' if wired else 'has no input behind it'}",
                       observed=show(r), expected="8,%02X" % (1 << bit) if wired else "0,00",
                       rule=rule)
            if wired:
                answers(ctx, r, "8,%02X" % (1 << bit),
                        f"ST{cause} names IN{bit} of port I{port}", rule="10.3.status.meaning")


@case("1.profile.parameter-ranges",
      rules=("1.profile.v-b-range", "1.profile.v-b-range-gve54", "1.profile.dollar-range",
             "10.cmd.modal", "10.cmd.accel-range", "10.cmd.override", "10.cmd.axis-limits",
             "10.cmd.axis-limits-clamped", "5.code.range"))
def ranges(ctx: CaseContext) -> None:
    p = ctx.profile
    for name, template, rule in _ranged(p):
        lo, hi = p.ranges[name].lo, p.ranges[name].hi
        for value, want in ((lo - 1, ErrorCode.RANGE), (lo, ErrorCode.OK), (hi, ErrorCode.OK),
                            (hi + 1, ErrorCode.RANGE)):
            body = template.format(*[value] * template.count("{}"))
            code(ctx, ctx.link.send(body), want, f"{body} → {want}",
                 rule=_past_top(p, name, rule) if value > hi else rule)
    if "VL" in p.commands and p.ranges["VL"].hi > p.max_rate:
        hi = p.ranges["VL"].hi
        code(ctx, ctx.link.send(f"VL{hi},{hi},{hi}"), ErrorCode.OK,
             f"VL above the variant's {p.max_rate} is accepted (clamped)",
             rule="10.cmd.axis-limits-clamped")
    else:
        code(ctx, ctx.link.send("VL1000,1000,1000" if "VL" in p.commands else "V1000"),
             ErrorCode.OK,
             "a rate in pulses/s within the variant's maximum is accepted as it is",
             rule="10.cmd.axis-limits-clamped" if "VL" in p.commands else "10.cmd.modal")


# on a real unit the guard sends no vector beyond --max-travel: COULD-NOT-TEST there
@case("1.profile.vector-range.limits", rules=("1.profile.vector-range",))
def vector_range(ctx: CaseContext) -> None:
    top = ctx.profile.vector_range
    setup(ctx, "H", expect="8")              # vectors wait in the queue while INTA = 1
    code(ctx, ctx.link.send(f"C{top},0,0"), ErrorCode.OK,
         f"a component of {top} is in range", inta=True)
    code(ctx, ctx.link.send(f"C0,{-top},0"), ErrorCode.OK, f"and of {-top}", inta=True)
    code(ctx, ctx.link.send(f"C{top + 1},0,0"), ErrorCode.RANGE,
         f"{top + 1} is out of range", inta=True)
    setup(ctx, "D")


@case("1.profile.version",
      rules=("1.profile.version", "2.link.serial-8n1", "3.frame.grammar"))
def version(ctx: CaseContext) -> None:
    """? answers 0,<the profile's firmware string>."""
    answers(ctx, ctx.link.send("?"), "0," + ctx.profile.version, "the firmware string",
            rule="1.profile.version")
