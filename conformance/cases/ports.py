"""Sections 10, 10.3: the ports bit by bit and the status words at their ends. Each bit
of every input port read with only its pin grounded, each bit of `O0` driven alone (the
rig reads both); every status word written 00 and FF and read back, and just beyond
(`SW n,100`) refused with 5 and leaving the word as it was."""

from __future__ import annotations

from conformance.case import CaseContext, case
from conformance.cases._kit import answers, code

#: the status words written at their ends (ST6's bits act: written 00 only, idle)
WORDS = range(6)


@case("10.cmd.ports.bit-by-bit", rig=True,
      rules=("10.cmd.port-bits", "10.cmd.inputs", "10.cmd.output"))
def ports(ctx: CaseContext) -> None:
    link, rule = ctx.link, "10.cmd.port-bits"
    answers(ctx, link.send("SW0,00"), "0", "interrupts off", rule="10.cmd.inputs")
    answers(ctx, link.send("SW1,00"), "0", "interrupts off", rule="10.cmd.inputs")
    for port in ctx.profile.input_ports:
        for level in [0xFF ^ (1 << bit) for bit in range(8)] + [0x00, 0xFF]:
            link.rig.set_input(port, level)
            answers(ctx, link.send(f"I{port}"), "0,%02X" % level,
                    f"I{port} with {'no pin' if level == 0xFF else 'pins'} grounded: "
                    f"{level:08b}", rule=rule)
    for level in [0xFF ^ (1 << bit) for bit in range(8)] + [0x00, 0xFF]:
        answers(ctx, link.send("O0,%02X" % level), "0", "O0,%02X" % level, rule="10.cmd.output")
        seen = link.rig.outputs()
        ctx.expect(seen == level, f"the outputs read {level:08b}", observed=f"{seen:08b}",
                   expected=f"{level:08b}", rule=rule)
    code(ctx, link.send("O0,100"), 5, "O0,100: one beyond FF → 5", rule="10.cmd.output")
    seen = link.rig.outputs()
    ctx.expect(seen == 0xFF, "the refused O0,100 left the outputs off", observed=seen,
               expected=0xFF, rule="10.cmd.output")


@case("10.3.status.register-ends",
      rules=("10.3.status.all-bits", "10.cmd.status-words", "5.code.range"))
def register_ends(ctx: CaseContext) -> None:
    link = ctx.link
    for n in WORDS:
        for value in ("FF", "00", "FF"):
            r = link.send(f"SW{n},{value}")     # may interrupt: only the code matters here
            ctx.require(r is not None and r.code == 0, f"SW{n},{value} answered {r}")
            r = link.send(f"SR{n}")
            ctx.expect(r is not None and r.values == [value], f"SR{n} after SW{n},{value}",
                       observed=r.text if r else None, expected=value,
                       rule="10.3.status.all-bits")
        code(ctx, link.send(f"SW{n},100"), 5, f"SW{n},100: one beyond FF → 5",
             inta=None, rule="5.code.range")
        r = link.send(f"SR{n}")
        ctx.expect(r is not None and r.values == ["FF"], f"ST{n} still FF after the refusal",
                   observed=r.text if r else None, expected="FF", rule="10.cmd.status-words")
        link.send(f"SW{n},00")
        link.send("D")                          # whatever an interrupt left
    answers(ctx, link.send("SW6,00"), "0", "SW6,00 when idle", rule="10.cmd.status-words")
    answers(ctx, link.send("SR6"), "0,00", "SR6: ST6 idle", rule="10.cmd.status-words")
    code(ctx, link.send("SW6,100"), 5, "SW6,100: one beyond FF → 5", rule="5.code.range")
