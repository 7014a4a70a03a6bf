"""Spec section 10.6, EEPROM: the cases that check it.

The 256 bytes that outlive restarts."""

from __future__ import annotations

from conformance.case.context import CaseContext, case
from conformance.cases._kit import answers, code, refused_beyond_ff, setup, show, vector
from conformance.link.account import Spent
from gve_fixtures.protocol import ErrorCode

#: bytes no profile gives a default to (spec 10.6)
UNWRITTEN = (0x00, 0x20, 0x7F, 0xFF)


def _restart(ctx: CaseContext, how: str = "J") -> None:
    if how == "J":
        r = ctx.link.send("J")
        ctx.require(r is not None and r.ok, "J answered")
    else:
        ctx.link.rig.power_on()
    ctx.link.wait(2.5, Spent.MANUAL)


#: the two patterns: each address's byte differs from every other address's, and the
#: second pass flips every bit of the first
PATTERNS = (0x5A, 0xA5)


# a unit known never to have been written: the emulator's (a real unit's may have been)
@case("10.6.eeprom.as-shipped", rig=True,
      rules=("10.6.eeprom.defaults", "10.6.eeprom.erased", "3.params.hex-digits"))
def as_shipped(ctx: CaseContext) -> None:
    # the bytes a manual names (the profile's defaults; the GVE54's manual names none)
    defaults = ctx.profile.eeprom.defaults
    for address, value in defaults.items():
        answers(ctx, ctx.link.send("ER%02X" % address), "0,%02X" % value,
                f"EEPROM {address:02X} as shipped", rule="10.6.eeprom.defaults")
    for address in (a for a in UNWRITTEN if a not in defaults):
        answers(ctx, ctx.link.send("ER%02X" % address), "0,FF",
                f"EEPROM {address:02X} never written: erased", rule="10.6.eeprom.erased")
    refused_beyond_ff(ctx, ctx.link.send("ER100"), "256 bytes: ER100 is out of range",
                      rule="10.6.eeprom.defaults")


@case("10.6.eeprom.every-address", destructive=True,
      rules=("10.cmd.eeprom-bytes", "10.6.eeprom.defaults", "3.params.hex-digits"))
def every_address(ctx: CaseContext) -> None:
    link = ctx.link
    size = ctx.profile.eeprom.size
    for key in PATTERNS:
        refused = []
        for address in range(size):
            r = link.send("EW%02X,%02X" % (address, address ^ key))
            if r is None or not r.ok:
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
    refused_beyond_ff(ctx, link.send("EW%X,00" % size),
                      f"{size} bytes: EW{size:X} is out of range", rule="10.6.eeprom.defaults")
    refused_beyond_ff(ctx, link.send("ER%X" % size), f"and ER{size:X}",
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


@case("10.6.eeprom.kept-across-j", destructive=True, rules=("10.6.eeprom.kept",))
def kept_across_j(ctx: CaseContext) -> None:
    """A byte written, `J`, the byte read back once the unit is ready (spec 2: about
    2 s); the session puts the byte back as found after the case."""
    link = ctx.link
    r = link.send("ER40")
    ctx.require(r is not None and r.ok and r.values, "ER40 answered")
    new = r.hex() ^ 0x5A
    setup(ctx, "EW40,%02X" % new)
    answers(ctx, link.send("ER40"), "0,%02X" % new, "ER40 reads the byte written")
    _restart(ctx, "J")
    answers(ctx, link.send("ER40"), "0,%02X" % new, "the byte written is kept across J")


@case("10.6.eeprom.refused-while-moving", destructive=True, rules=("5.code.busy-eeprom",))
def busy(ctx: CaseContext) -> None:
    link = ctx.link
    r = link.send("ER41")
    ctx.require(r is not None and r.ok and r.values, "ER41 answered")
    before = r.hex()
    setup(ctx, "L" + vector(ctx, 1000))
    link.wait(0.1)
    words = (("EFW44,1.5", "EFW"), ("EUW48,7", "EUW"))
    writes = ["EW41,%02X" % (before ^ 0xFF)]
    writes += [body for body, name in words if name in ctx.profile.commands]
    for body in writes:
        code(ctx, link.send(body), ErrorCode.BUSY, f"{body} while moving → 7")
    link.send("H")
    answers(ctx, link.send("ER41"), f"8,{before:02X}", "the refused write changed nothing")


@case("10.6.eeprom.round-trip",
      rules=("10.cmd.eeprom-bytes",),
      tag="M", destructive=True)
def eeprom(ctx: CaseContext) -> None:
    """EW writes a byte that ER reads back (kept, then restored by the suite)"""
    link = ctx.link
    r = link.send("ER40")
    ctx.require(r is not None and r.ok, "ER40 answered")
    old = r.hex()
    new = old ^ 0x5A
    answers(ctx, link.send("EW40,%02X" % new), "0", "EW40 → 0")
    answers(ctx, link.send("ER40"), "0,%02X" % new, "ER40 reads the new byte")


@case("10.6.eeprom.words",
      rules=("10.cmd.eeprom-words", "3.params.word-values-decimal"),
      destructive=True,
      requires=("EFW", "EUW"))
def words(ctx: CaseContext) -> None:
    """EFW/EFR store float32 and EUW/EUR uint32 little-endian."""
    link = ctx.link
    words = "10.cmd.eeprom-words"
    answers(ctx, link.send("EFW30,0.25"), "0", "EFW30,0.25", rule=words)
    answers(ctx, link.send("EFR30"), "0,0.25", "EFR30 → 0.25", rule=words)
    answers(ctx, link.send("ER33"), "0,3E", "the float's top byte at 33 (little-endian)",
            rule=words)
    answers(ctx, link.send("EUW40,305419896"), "0", "EUW40", rule=words)
    answers(ctx, link.send("ER40"), "0,78", "the uint's low byte first", rule=words)
    code(ctx, link.send("EFRFD"), ErrorCode.RANGE, "a word past FF → 5", rule=words)
