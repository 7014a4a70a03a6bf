"""Spec section 7, Packets `*S` / `*E`: the cases that check it.

`*S` … `*E n`: several `C` and `B` frames sent as one."""

from __future__ import annotations

from conformance.case.context import CaseContext, case
from conformance.cases._kit import (
    answers,
    code,
    fill_queue,
    finished,
    index,
    position,
    queries_counted,
    setup,
    show,
    still_seconds,
    vector,
)
from conformance.link.framing import byte_sum
from conformance.motion.probe import Probe
from gve_fixtures.protocol import ErrorCode


def _packet(ctx: CaseContext, members: list[str], count: int):
    link = ctx.link
    link.send("*S", answer=False)
    for m in members:
        link.send(m, answer=False)
    return link.send(f"*E{count}")


#: packets that fail, each with a B member that must not be set: (members, *E's n, answer)
FAILING = (
    (["B10", "C0,50,0", "C0,50,0"], 4, "2,3"),       # count mismatch
    (["B20", "C0,50,0", "V100"], 3, "4,3"),          # a member that may not be one
    (["B30", "B1", "C0,50,0"], 3, "5,3"),            # a member out of range
)


@case("7.packet.bad-checksum-member.corrupted-end", requires=("*S",),
      rules=("7.packet.bad-checksum-member", "8.index.uncounted", "7.packet.open-until-end",
             "8.index.packet-frames-counted"))
def corrupted_end(ctx: CaseContext) -> None:
    """The corrupted *E leaves the packet open past the longest watchdog a unit may take
    (the link waits it out after the frame timed out): a packet a watchdog closed by then
    is its rule's reading, answered 2,k on its own."""
    link = ctx.link
    setup(ctx, "%+", checksum=False)
    before = index(ctx)
    link.send("*S", answer=False)
    link.send("C" + vector(ctx, 1), answer=False)
    r = link.send("*E1", checksum="00", timeout=0.5)
    ctx.expect(r is None, "a corrupted *E is a failing member: no answer", observed=r,
               expected="nothing", rule="7.packet.bad-checksum-member")
    answers(ctx, link.send("*E1"), "2,2,%02X" % byte_sum(b"2,2,"),
            "the packet stayed open with two members",
            rule="7.packet.bad-checksum-member")
    # the member counts; *S and *E by our reading only (8.index.packet-frames-counted)
    counted = queries_counted(ctx)
    after = index(ctx)
    moved = None if before is None or after is None else (after - before - counted) % 256
    ctx.expect(moved in (1, 3), "*S, the member and *E counted; the corrupted frame not",
               observed=after, expected=None if before is None else (before + 3) % 256,
               rule="8.index.uncounted")
    if moved == 1:
        ctx.expect(False, "*S and *E counted", observed=after,
                   expected=(before + 3) % 256, rule="8.index.packet-frames-counted")
    ctx.link.wait(still_seconds(ctx))
    ctx.expect_equal(position(ctx), [0, 0, 0], "nothing was committed",
                     rule="7.packet.bad-checksum-member")


@case("7.packet.commits-all",
      rules=("7.packet.exchange", "7.packet.members", "7.packet.all-or-nothing"),
      tag="M", requires=("*S",))
def commits(ctx: CaseContext) -> None:
    """*E<n> commits every member in order and answers code,k."""
    r = _packet(ctx, ["B500", "C" + vector(ctx, 10), "C" + vector(ctx, 0, 20)], 3)
    answers(ctx, r, "0,3", "a good packet → 0,3", rule="7.packet.exchange")
    finished(ctx, 30)
    ctx.expect_equal(position(ctx), [10, 20, 0], "both vectors ran", rule="7.packet.exchange")


@case("7.packet.count-mismatch",
      rules=("7.packet.codes", "7.packet.all-or-nothing", "5.code.watchdog"),
      requires=("*S",))
def count(ctx: CaseContext) -> None:
    """k ≠ n: nothing is committed and *E answers 2,k."""
    r = _packet(ctx, ["C" + vector(ctx, 10), "C" + vector(ctx, 10)], 3)
    # the code is the manual's (2 for a count that differs); the count k our reading
    code(ctx, r, ErrorCode.COUNT_MISMATCH, "2 members, *E3 → 2", rule="5.code.watchdog")
    ctx.expect(r is not None and r.values[:1] == ["2"], "and the 2 members received",
               observed=show(r), expected="2,2", rule="7.packet.codes")
    ctx.link.wait(still_seconds(ctx))
    # members committed as they arrive are another reading of the manual's packet [D]
    ctx.expect(position(ctx) == [0, 0, 0], "nothing moved", rule="7.packet.all-or-nothing")


@case("7.packet.end-without-start",
      rules=("7.packet.breakers",),
      requires=("*S",))
def end_alone(ctx: CaseContext) -> None:
    """*E with no open packet answers 4,0."""
    answers(ctx, ctx.link.send("*E1"), "4,0", "*E1 alone → 4,0")


@case("7.packet.failed-leaves-nothing", requires=("*S",), timing=True,
      rules=("7.packet.all-or-nothing", "7.packet.codes"))
def failed_packet(ctx: CaseContext) -> None:
    link = ctx.link
    start = position(ctx)
    for members, n, want in FAILING:
        link.send("*S", answer=False)
        for m in members:
            link.send(m, answer=False)
        answers(ctx, link.send(f"*E{n}"), want, f"{', '.join(members)}, *E{n} → {want}",
                rule="7.packet.codes")
    link.wait(0.3)
    ctx.expect_equal(position(ctx), start, "no C member moved", rule="7.packet.all-or-nothing")
    code(ctx, link.send("L" + vector(ctx, 0)), ErrorCode.OK,
         "nothing was queued: L0,0,0 → 0 at once",
         rule="7.packet.all-or-nothing")
    # B is the junction's rate: at the reset B two C pass their junction at speed, at
    # B10..B30 they would all but stop there
    Probe(ctx, "the junction at the reset B after the failed packets",
          "7.packet.all-or-nothing").script(["A5", "V2000", "C700,0,0", "C700,0,0", 1.0])


@case("7.packet.halt-inside",
      rules=("7.packet.breakers", "8.index.counts", "8.index.packet-frames-counted"),
      requires=("*S",))
def breakers(ctx: CaseContext) -> None:
    """H, @, > inside an open packet are answered at once and discard the packet."""
    link = ctx.link
    before = index(ctx)
    link.send("*S", answer=False)
    link.send("C" + vector(ctx, 10), answer=False)
    # that @ is answered inside a packet (and closes it) is our reading [D]; a unit that
    # takes it as a member answers nothing, and the session closes the packet with *E
    counted = queries_counted(ctx)
    r = link.send("@")
    if not ctx.expect(r is not None and r.ok, "@ inside a packet is answered at once",
                      observed=r, expected="0,<index>", rule="7.packet.breakers"):
        return
    expected = None if before is None else (before + 2 + counted) % 256
    got = link.index_value(r) if r.values else None
    # the member counts by the manual; the *S only by our reading (the manuals count
    # only a packet's members among its commands)
    member_only = None if expected is None else (expected - 1) % 256
    ctx.expect(got is not None and got in (expected, member_only), "the member counted",
               observed=r, expected=f"0,{expected}", rule="8.index.counts")
    if got == member_only:
        ctx.expect(False, "*S counted", observed=r, expected=f"0,{expected}",
                   rule="8.index.packet-frames-counted")
    answers(ctx, link.send("*E1"), "4,0", "the packet was discarded", rule="7.packet.breakers")


@case("7.packet.invalid-member",
      rules=("7.packet.other-member", "7.packet.codes", "7.packet.all-or-nothing"),
      requires=("*S",))
def invalid(ctx: CaseContext) -> None:
    """A member other than C or B fails the packet with 4; nothing is committed."""
    r = _packet(ctx, ["C" + vector(ctx, 10), "V100", "C" + vector(ctx, 10)], 3)
    answers(ctx, r, "4,3", "V inside a packet → 4,3", rule="7.packet.codes")
    ctx.link.wait(still_seconds(ctx))
    ctx.expect_equal(position(ctx), [0, 0, 0], "no member was committed",
                     rule="7.packet.all-or-nothing")


@case("7.packet.no-room",
      rules=("7.packet.codes", "5.code.queue-full", "7.packet.all-or-nothing"),
      requires=("*S",))
def no_room(ctx: CaseContext) -> None:
    """A packet that does not fit the queue answers 1 and commits nothing."""
    if not fill_queue(ctx, ctx.profile.buffer - 1, rule="5.code.queue-full"):
        return
    r = _packet(ctx, ["C" + vector(ctx, 1), "C" + vector(ctx, -1)], 2)
    ctx.expect(r is not None and (r.code, r.values) == (ErrorCode.QUEUE_FULL, ["2"]),
               "2 vectors into 1 free place → 1,2 (9,2 while INTA)", observed=r,
               expected="9,2", rule="7.packet.codes")
    r = ctx.link.send("F")
    ctx.expect(r is not None and r.values == ["D0"], "the queue is not full (nothing added)",
               observed=r, expected="8,D0", rule="7.packet.all-or-nothing")
    ctx.link.send("D")


@case("7.packet.out-of-range-member",
      rules=("7.packet.codes",),
      requires=("*S",))
def out_of_range(ctx: CaseContext) -> None:
    """A member out of range fails the packet with its code (5)"""
    r = _packet(ctx, ["B1", "C" + vector(ctx, 10)], 2)
    answers(ctx, r, "5,2", "B1 (below range) → 5,2")


@case("7.packet.with-checksums",
      rules=("7.packet.checksums",),
      requires=("*S",))
def summed(ctx: CaseContext) -> None:
    """Packets work in checksum mode, each member with its own checksum."""
    setup(ctx, "%+", checksum=False)
    r = _packet(ctx, ["C" + vector(ctx, 10), "C" + vector(ctx, 10)], 2)
    ctx.expect(r is not None and r.ok and r.values == ["2"] and r.checksum_ok,
               "a summed packet → 0,2 with its checksum", observed=r, expected="0,2,XX")
