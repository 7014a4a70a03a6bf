"""Sections 2, 5, 6, 9, 10.6: the EEPROM (defaults, erased bytes, kept across J and
power cycles, never copied into the status words, words and their float syntax, refused
while moving) and what a restart resets and what it does not."""

from __future__ import annotations

from conformance.case import CaseContext, case
from conformance.cases._kit import answers, code, setup, show, vector

#: bytes no profile gives a default to (spec 10.6)
UNWRITTEN = (0x00, 0x20, 0x7F, 0xFF)


def _restart(ctx: CaseContext, how: str = "J") -> None:
    if how == "J":
        r = ctx.link.send("J")
        ctx.require(r is not None and r.code == 0, "J answered")
    else:
        ctx.link.rig.power_on()
    ctx.link.wait(2.5)


# a unit known never to have been written: the emulator's (a real unit's may have been)
@case("10.6.eeprom.as-shipped", rig=True, rules=("10.6.eeprom.defaults", "10.6.eeprom.erased"))
def as_shipped(ctx: CaseContext) -> None:
    defaults = {0x05: 0xFF, 0x0D: 0xFF, **({0x01: 0x00} if ctx.profile.family == "GVE84" else {})}
    for address, value in defaults.items():
        answers(ctx, ctx.link.send("ER%02X" % address), "0,%02X" % value,
                f"EEPROM {address:02X} as shipped", rule="10.6.eeprom.defaults")
    for address in UNWRITTEN:
        answers(ctx, ctx.link.send("ER%02X" % address), "0,FF",
                f"EEPROM {address:02X} never written: erased", rule="10.6.eeprom.erased")
    code(ctx, ctx.link.send("ER100"), 5, "256 bytes: 100 is out of range",
         rule="10.6.eeprom.defaults")


@case("10.6.eeprom.kept-across-restarts", destructive=True, rig=True,
      rules=("10.6.eeprom.kept", "9.reset.eeprom-not-copied"))
def kept(ctx: CaseContext) -> None:
    link = ctx.link
    setup(ctx, "EW40,5A")
    setup(ctx, "EW08,FF")                     # the interrupt enables kept in the EEPROM
    _restart(ctx, "J")
    answers(ctx, link.send("ER40"), "0,5A", "kept across J", rule="10.6.eeprom.kept")
    _restart(ctx, "power-on")
    answers(ctx, link.send("ER40"), "0,5A", "kept across a power cycle",
            rule="10.6.eeprom.kept")
    for n in range(4):
        answers(ctx, link.send(f"SR{n}"), "0,00", f"ST{n} is not loaded from the EEPROM",
                rule="9.reset.eeprom-not-copied")


@case("10.6.eeprom.refused-while-moving", destructive=True, rules=("5.code.busy-eeprom",))
def busy(ctx: CaseContext) -> None:
    link = ctx.link
    r = link.send("ER41")
    ctx.require(r is not None and r.code == 0 and r.values, "ER41 answered")
    before = r.hex()
    setup(ctx, "L" + vector(ctx, 1000))
    link.wait(0.1)
    words = (("EFW44,1.5", "EFW"), ("EUW48,7", "EUW"))
    writes = ["EW41,%02X" % (before ^ 0xFF)]
    writes += [body for body, name in words if name in ctx.profile.commands]
    for body in writes:
        code(ctx, link.send(body), 7, f"{body} while moving → 7")
    link.send("H")
    answers(ctx, link.send("ER41"), f"8,{before:02X}", "the refused write changed nothing")


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


@case("2.link.restart", destructive=True, timing=True,
      rules=("2.link.restart-deaf", "2.link.ready-after-restart", "6.checksum.off-after-reset",
             "10.cmd.restart"))
def restart(ctx: CaseContext) -> None:
    link = ctx.link
    summed = "%" in ctx.profile.commands
    if summed:
        setup(ctx, "%+", checksum=False)
    answers(ctx, link.send("J"), "0", "J answers a plain 0 (no checksum)", rule="10.cmd.restart")
    link.wait(0.5)
    r = link.send("SW3,5A", checksum=False, timeout=1.0)
    ctx.expect(r is None, "a frame while the unit restarts gets no answer",
               observed=r, expected="nothing", rule="2.link.restart-deaf")
    link.wait(2.5)
    r = link.send("@", checksum=False)
    ctx.expect(r is not None and r.raw == b"0,0\r", "it was lost: the index is 0",
               observed=r, expected="0,0", rule="2.link.restart-deaf")
    answers(ctx, link.send("SR3", checksum=False), "0,00", "ready again, ST3 unwritten",
            rule="2.link.ready-after-restart")
    if summed:
        answers(ctx, link.send("SR0", checksum=False), "0,00",
                "checksums are off after J: a frame without one is executed",
                rule="6.checksum.off-after-reset")


#: the two patterns: each address's byte differs from every other address's, and the
#: second pass flips every bit of the first
PATTERNS = (0x5A, 0xA5)


@case("10.6.eeprom.every-address", destructive=True,
      rules=("10.cmd.eeprom-bytes", "10.6.eeprom.defaults"))
def every_address(ctx: CaseContext) -> None:
    link = ctx.link
    size = ctx.profile.eeprom.size
    for key in PATTERNS:
        refused = []
        for address in range(size):
            r = link.send("EW%02X,%02X" % (address, address ^ key))
            if r is None or r.code != 0:
                refused.append(f"EW{address:02X} → {show(r)}")
        ctx.expect(not refused, f"EW writes every address (byte = address XOR {key:02X})",
                   observed="; ".join(refused) or "every one answered 0",
                   expected="0 each time", rule="10.cmd.eeprom-bytes")
        wrong = []
        for address in range(size):
            r = link.send("ER%02X" % address)
            want = "0,%02X" % (address ^ key)
            if r is None or r.raw != want.encode() + b"\r":
                wrong.append(f"ER{address:02X} → {show(r)} (wrote {address ^ key:02X})")
        ctx.expect(not wrong, f"ER reads back each address's own byte ({key:02X} pattern)",
                   observed="; ".join(wrong[:8]) + (f" … {len(wrong)} in all" if wrong else "")
                   or "every byte as written",
                   expected="0,<address XOR %02X> at each address" % key,
                   rule="10.cmd.eeprom-bytes")
    code(ctx, link.send("EW%X,00" % size), 5, f"{size} bytes: EW{size:X} is out of range",
         rule="10.6.eeprom.defaults")
    code(ctx, link.send("ER%X" % size), 5, f"and ER{size:X}", rule="10.6.eeprom.defaults")
