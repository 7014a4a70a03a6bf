"""Spec section 2, Link: the cases that check it.

The serial line: its format, the addresses on it and who may speak when."""

from __future__ import annotations

from conformance.case.context import CaseContext, case
from conformance.cases._kit import answers, index, index_moved, setup
from conformance.link.account import Spent
from conformance.link.framing import frame
from conformance.link.link import MARGIN
from conformance.motion.tolerance import byte_ns


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


@case("2.link.other-address-ignored",
      rules=("2.link.addressed-only", "3.frame.other-address-whole", "8.index.uncounted"))
def other_address(ctx: CaseContext) -> None:
    """Only the addressed unit answers; a frame for another address is ignored whole."""
    link = ctx.link
    other = (link.address + 1) % 8
    if other == 7:
        other = (other + 1) % 8
    before = index(ctx)
    link.send("V2000", address=other, answer=False)
    got = link.wait(0.3)
    ctx.expect(got == b"", "no answer to another address", observed=got, expected=b"",
               tag="always", rule="2.link.addressed-only")
    index_moved(ctx, before, 0, "the ignored frame did not count in the index",
                rule="8.index.uncounted")


@case("2.link.restart", destructive=True, timing=True,
      rules=("2.link.restart-deaf", "2.link.ready-after-restart", "6.checksum.off-after-reset",
             "10.cmd.restart"))
def restart(ctx: CaseContext) -> None:
    link = ctx.link
    summed = "%" in ctx.profile.commands
    if summed:
        setup(ctx, "%+", checksum=False)
    answers(ctx, link.send("J"), "0", "J answers a plain 0 (no checksum)", rule="10.cmd.restart")
    link.wait(0.5, Spent.MANUAL)             # into the restart (spec 2, M84 12.4)
    r = link.send("SW3,5A", checksum=False, timeout=1.0)
    ctx.expect(r is None, "a frame while the unit restarts gets no answer",
               observed=r, expected="nothing", rule="2.link.restart-deaf")
    link.wait(2.5, Spent.MANUAL)
    r = link.send("@", checksum=False)
    ctx.expect(r is not None and r.ok and len(r.values) == 1 and link.index_value(r) == 0,
               "it was lost: the index is 0",
               observed=r, expected="0,0", rule="2.link.restart-deaf")
    answers(ctx, link.send("SR3", checksum=False), "0,00", "ready again, ST3 unwritten",
            rule="2.link.ready-after-restart")
    if summed:
        answers(ctx, link.send("SR0", checksum=False), "0,00",
                "checksums are off after J: a frame without one is executed",
                rule="6.checksum.off-after-reset")
