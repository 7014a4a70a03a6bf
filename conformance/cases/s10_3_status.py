"""Spec section 10.3, Status words: the cases that check it.

ST0..ST6: interrupt enables, polarities, causes, and the stepper's state."""

from __future__ import annotations

from conformance.case.context import CaseContext, case
from conformance.cases._kit import (
    answers,
    code,
    finished,
    halted_line,
    position,
    refused_beyond_ff,
    setup,
    show,
    still_seconds,
    vector,
)
from conformance.link.account import Spent
from gve_fixtures.protocol import ErrorCode

IN0_ACTIVE = 0xFE          # IN0 grounded: active at the reset polarity 0 (spec 10.3)


def _interrupted_by_input(ctx: CaseContext) -> bool:
    """IN0 enabled while it is active: the unit is interrupted (INTA, ST4 bit 0) at once
    under the level reading [D]. A unit may see the level only after it has answered
    the write, so SR6 asks; one that never does reads interrupts as edges (False)."""
    r = ctx.link.send("SW0,01")
    ctx.require(r is not None and r.ok, f"SW0,01 answered {show(r)}")
    if not r.inta:
        r = ctx.link.send("SR6")
    return ctx.expect(r is not None and r.inta, "enabling IN0 while it is active interrupts",
                      observed=show(r), expected="INTA set", rule="10.3.inputs.level-triggered")


def _after_clearing(ctx: CaseContext, body: str) -> None:
    if not _interrupted_by_input(ctx):
        return                            # edges, not levels: what follows is moot
    r = ctx.link.send(body)
    if body == "R":
        # nothing was kept: what R answers then is the restore rule's reading, the INTA
        # bit on that answer this case's
        code(ctx, r, ErrorCode.OK, "R with nothing kept → 0", rule="10.5.restore.pops")
        ctx.expect(r is not None and r.inta is True, "R with the input still active: INTA "
                   "set on the answer", observed=show(r), expected="INTA bit set",
                   rule="4.response.inta-level")
    else:
        code(ctx, r, ErrorCode.OK, f"{body} with the input still active → 8", inta=True,
             rule="4.response.inta-level")
    for n, value in ((6, "80"), (4, "01")):
        r = ctx.link.send(f"SR{n}")
        ctx.expect(r is not None and r.inta and r.values == [value],
                   f"after {body}: ST{n} set again at once", observed=show(r),
                   expected=f"8,{value}", rule="10.3.inputs.level-triggered")
    code(ctx, ctx.link.send("L" + vector(ctx, 300)), ErrorCode.OK,
         f"after {body}: L is accepted and waits", inta=True,
         rule="10.3.inputs.level-triggered")
    ctx.link.wait(still_seconds(ctx))
    here = position(ctx)
    ctx.expect(here == [0, 0, 0], f"after {body}: nothing moved while the input is active",
               observed=here, expected=[0, 0, 0], rule="10.3.inputs.level-triggered")


#: the status words written at their ends (ST6's bits act: written 00 only, idle)
WORDS = range(6)


def _in0_was_the_cause(ctx: CaseContext, what: str, *, rule: str) -> None:
    """ST4 names IN0 (bit 0) as the interrupt's cause, and INTA is set (spec 10.3)."""
    r = ctx.link.send("SR4")
    ctx.expect(r is not None and r.inta and r.values[:1] == ["01"], what, observed=show(r),
               expected="8,01", rule=rule)


@case("10.3.flags.f-command",
      rules=("10.cmd.flags", "3.params.none-expected"))
def f_idle(ctx: CaseContext) -> None:
    answers(ctx, ctx.link.send("F"), "0,00", "F when idle", rule="10.cmd.flags")
    code(ctx, ctx.link.send("F1"), ErrorCode.SYNTAX,
         "F takes no parameters", rule="3.params.none-expected")


@case("10.3.inputs.level-after-clearing", hands=True,
      rules=("10.3.inputs.level-triggered", "4.response.inta-level", "10.5.restore.pops"))
def level_after_clearing(ctx: CaseContext) -> None:
    for body in ("G", "D", "K", "R"):
        ctx.fresh_link()
        with ctx.operator.grounded(1, 0, "the X reference input"):
            _after_clearing(ctx, body)


@case("10.3.inputs.physical-across-restart", rig=True, destructive=True,
      rules=("10.3.inputs.physical",))
def physical(ctx: CaseContext) -> None:
    link = ctx.link
    link.rig.set_input(1, IN0_ACTIVE)
    answers(ctx, link.send("J"), "0", "J → 0", tag="D")
    link.wait(2.5, Spent.MANUAL)
    answers(ctx, link.send("I1"), "0,FE", "after J the grounded input still reads 0")
    link.rig.power_on()
    link.wait(2.5, Spent.MANUAL)
    answers(ctx, link.send("I1"), "0,FE", "after power-on the grounded input still reads 0")


@case("10.3.interrupt.polarity",
      rules=("10.3.inputs.polarity", "4.response.inta-level"),
      hands=True)
def polarity(ctx: CaseContext) -> None:
    """An input is active when its level equals its polarity bit."""
    ctx.operator.release(1, 0, "the X reference input")     # unconnected: reads 1
    setup(ctx, "SW0,01")                 # IN0 enabled; unconnected (1) is inactive at 0
    # IN0 active at log. 1: the unconnected input becomes active, an interrupt whether
    # inputs are level- or edge-triggered (level is our reading [D])
    r = ctx.link.send("SW2,01")
    ctx.expect(r is not None and r.ok and r.inta, "making it active interrupts at once",
               observed=show(r), expected="8", rule="4.response.inta-level")
    _in0_was_the_cause(ctx, "an unconnected input with polarity 1 interrupts at once",
                      rule="10.3.inputs.polarity")


@case("10.3.interrupt.stops-motion",
      rules=("10.3.inputs.interrupt", "10.3.status.meaning"), rig=True)
def interrupt(ctx: CaseContext) -> None:
    """An enabled active input stops the motion, sets its cause bit and INTA."""
    link = ctx.link
    setup(ctx, "SW0,01")
    setup(ctx, "C" + vector(ctx, 3000))
    link.wait(0.3)
    link.rig.set_input(1, 0xFE)          # IN0 grounded: active at polarity 0
    link.wait(1.0)
    here = position(ctx)
    link.wait(0.5)
    ctx.expect_equal(position(ctx), here, "stopped", rule="10.3.inputs.interrupt")
    _in0_was_the_cause(ctx, "ST4 bit 0, INTA", rule="10.3.status.meaning")


@case("10.3.status.all-bits-stored",
      rules=("10.3.status.all-bits", "10.cmd.status-words"))
def all_bits(ctx: CaseContext) -> None:
    """Every status word stores all 8 bits as written."""
    for n, value in ((2, "2B"), (3, "FF"), (5, "80"), (1, "3F"), (0, "A2")):
        r = ctx.link.send(f"SW{n},{value}")     # may interrupt: only the code matters here
        ctx.require(r is not None and r.ok, f"SW{n},{value} answered {show(r)}")
        r = ctx.link.send(f"SR{n}")
        ctx.expect(r is not None and r.values == [value], f"SR{n} after SW{n},{value}",
                   observed=show(r), expected=value, rule="10.3.status.all-bits")


@case("10.3.status.inputs-read-ff",
      rules=("10.3.inputs.idle-level", "10.cmd.inputs"))
def inputs(ctx: CaseContext) -> None:
    """Input ports read FF with nothing connected."""
    answers(ctx, ctx.link.send("I1"), "0,FF", "I1 with nothing connected",
            rule="10.3.inputs.idle-level")


@case("10.3.status.register-ends",
      rules=("10.3.status.all-bits", "10.cmd.status-words", "5.code.range",
             "3.params.hex-digits"))
def register_ends(ctx: CaseContext) -> None:
    link = ctx.link
    for n in WORDS:
        for value in ("FF", "00", "FF"):
            r = link.send(f"SW{n},{value}")     # may interrupt: only the code matters here
            ctx.require(r is not None and r.ok, f"SW{n},{value} answered {r}")
            r = link.send(f"SR{n}")
            ctx.expect(r is not None and r.values == [value], f"SR{n} after SW{n},{value}",
                       observed=r.text if r else None, expected=value,
                       rule="10.3.status.all-bits")
        refused_beyond_ff(ctx, link.send(f"SW{n},100"), f"SW{n},100: one beyond FF",
                          rule="5.code.range")
        r = link.send(f"SR{n}")
        ctx.expect(r is not None and r.values == ["FF"], f"ST{n} still FF after the refusal",
                   observed=r.text if r else None, expected="FF", rule="10.cmd.status-words")
        link.send(f"SW{n},00")
        link.send("D")                          # whatever an interrupt left
    answers(ctx, link.send("SW6,00"), "0", "SW6,00 when idle", rule="10.cmd.status-words")
    answers(ctx, link.send("SR6"), "0,00", "SR6: ST6 idle", rule="10.cmd.status-words")
    refused_beyond_ff(ctx, link.send("SW6,100"), "SW6,100: one beyond FF", rule="5.code.range")


@case("10.3.status.run-bit",
      rules=("10.3.st6.bits", "10.3.st6.inta-run"))
def run_bit(ctx: CaseContext) -> None:
    """ST6 bit 6 (RUN) is set while a vector is processed and clear when idle."""
    setup(ctx, "L" + vector(ctx, 500))
    r = ctx.link.send("SR6")
    ctx.expect(r is not None and r.values[:1] == ["40"], "RUN while moving",
               observed=show(r), expected="0,40", rule="10.3.st6.bits")
    finished(ctx, 30)
    answers(ctx, ctx.link.send("SR6"), "0,00", "idle again", rule="10.3.st6.inta-run")


@case("10.3.sw6.writing-st6", rules=("10.3.sw6.acts", "10.3.sw6.live-bits",
                                     "10.3.sw6.answer-inta", "4.response.inta-bit"))
def sw6(ctx: CaseContext) -> None:
    """SW6 sets and clears INTA: its own answer shows the write at once [D], the answers
    after it show it whatever the instant (spec 4 [M])."""
    link = ctx.link
    code(ctx, link.send("SW6,80"), ErrorCode.OK,
         "SW6,80 sets INTA", inta=True, rule="10.3.sw6.answer-inta")
    r = link.send("L" + vector(ctx, 100))
    code(ctx, r, ErrorCode.OK, "L is accepted while INTA = 1", rule="10.3.sw6.acts")
    ctx.expect(r is not None and bool(r.inta), "the answer after SW6,80 carries INTA",
               observed=show(r), expected="8", rule="4.response.inta-bit")
    link.wait(still_seconds(ctx))
    ctx.expect_equal(position(ctx), [0, 0, 0], "the vector waits for G", rule="10.3.sw6.acts")
    link = ctx.fresh_link()
    halted_line(ctx, 300, 0.1)
    code(ctx, link.send("SW6,00"), ErrorCode.OK,
         "SW6,00 clears INTA", inta=False, rule="10.3.sw6.answer-inta")
    r = link.poll("SR6", lambda r: r.values == ["00"], 10)
    ctx.expect(r is not None, "RUN clears when the resumed vector ends", observed=show(r),
               expected="0,00", rule="10.3.sw6.live-bits")
    ctx.expect_equal(position(ctx), [300, 0, 0], "the vector resumed to its target",
                     rule="10.3.sw6.acts")
    code(ctx, link.send("L" + vector(ctx, 0)), ErrorCode.OK, "idle again: L0,0,0 → 0",
         rule="10.3.sw6.live-bits")


def _two_stated(ctx: CaseContext, word: int) -> tuple[int, int, int] | None:
    """Two inputs a manual names behind a status word, and a third input of its port
    (wired or not): the sources of the several-at-once case."""
    mask = ctx.profile.stated_masks[word]
    named = [1 << b for b in range(8) if mask >> b & 1]
    if len(named) < 2:
        return None
    third = next(1 << b for b in range(8) if (1 << b) not in named[:2])
    return named[0], named[1], third


@case("10.3.interrupt.several-at-once", rig=True,
      rules=("10.3.status.meaning", "10.3.inputs.interrupt", "10.3.inputs.polarity",
             "10.3.st6.bits", "10.4.delete", "10.3.inputs.cause-accumulates"))
def several_at_once(ctx: CaseContext) -> None:
    """Two enabled inputs become active in one step, one grounded at polarity 0 and one
    released at polarity 1, beside a third that is grounded but not enabled: the cause
    word names both enabled ones and not the third; D clears it (not G: with nothing
    queued G may answer 6 and leave the flags, spec 5). Then the two one after the other:
    the second's bit added to the first's is the decision [D]."""
    for port, word in ((1, 0), (2, 1)):
        picked = _two_stated(ctx, word)
        if port not in ctx.profile.input_ports or picked is None:
            continue
        a, b, c = picked
        link = ctx.fresh_link()
        link.rig.set_input(port, 0xFF ^ b)          # b grounded: inactive at polarity 1
        setup(ctx, "SW%d,%02X" % (word + 2, b))
        setup(ctx, "SW%d,%02X" % (word, a | b))      # a, b enabled; none active yet
        link.rig.set_input(port, 0xFF ^ a ^ c)      # a, c grounded, b released: at once
        r = link.send(f"SR{word + 4}")
        want = "8,%02X" % (a | b)
        answers(ctx, r, want, f"I{port} inputs {a:02X} (grounded, polarity 0) and {b:02X} "
                f"(released, polarity 1) active at once, {c:02X} grounded but not enabled: "
                f"ST{word + 4} names the two enabled", rule="10.3.status.meaning")
        r = link.send("SR6")
        ctx.expect(r is not None and r.values[:1] == ["80"], "INTA set, INTCOM not (no H)",
                   observed=show(r), expected="8,80", rule="10.3.st6.bits")
        link.rig.set_input(port, 0xFF ^ b)          # every input inactive again
        code(ctx, link.send("D"), ErrorCode.OK, "D clears the interrupt", inta=False,
             rule="10.4.delete")
        answers(ctx, link.send(f"SR{word + 4}"), "0,00", f"D cleared ST{word + 4}",
                rule="10.4.delete")
        link.rig.set_input(port, 0xFF ^ a ^ b)      # a active: it interrupts
        link.rig.set_input(port, 0xFF ^ a)          # then b (released) while INTA = 1
        r = link.send(f"SR{word + 4}")
        ctx.expect(r is not None and r.inta and r.values[:1] and int(r.values[0], 16) & a,
                   f"the first input's bit ({a:02X}) names what stopped the unit",
                   observed=show(r), expected="8,%02X" % (a | b), rule="10.3.inputs.interrupt")
        answers(ctx, r, "8,%02X" % (a | b), "the second input's bit is added",
                rule="10.3.inputs.cause-accumulates")
    if not ctx.checks:
        ctx.require(False, "no status word with two interrupt inputs a manual names")
