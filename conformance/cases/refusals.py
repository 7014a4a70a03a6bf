"""Sections 4, 7, 10.1: what a refused frame leaves behind. A vector refused with 1 leaves
the queue exactly as it was (the vectors that run after it and where they end show it),
and a packet that fails leaves no effect of any member: no vector queued, no `B` set (a
junction at the reset `B`, measured)."""

from __future__ import annotations

from conformance.case import CaseContext, case
from conformance.cases._kit import answers, code, fill_queue, position, show, step_factor, vector
from conformance.motion.probe import Probe

#: the vectors refused for want of room, then sent again until accepted: along Y and Z,
#: where the queue's back-and-forth vectors along X never go
REFUSED_C, REFUSED_L = (0, 3, 0), (0, 0, 5)


@case("10.1.queue.refused-leaves-queue",
      rules=("5.code.queue-full", "10.1.queue.cont-buffer", "4.response.failed-not-executed"))
def refused_vector(ctx: CaseContext) -> None:
    link = ctx.link
    start = position(ctx)
    ctx.require(start is not None, "PF did not answer with positions")
    if not fill_queue(ctx):                  # H, then the buffer's size of ±1 along X
        return
    before = link.send("F")
    code(ctx, link.send("C" + vector(ctx, *REFUSED_C)), 1, "C into a full queue → 1 (9)",
         inta=True, rule="5.code.queue-full")
    code(ctx, link.send("L" + vector(ctx, *REFUSED_L)), 1, "L while vectors wait → 1 (9)",
         inta=True, rule="5.code.queue-full")
    after = link.send("F")
    ctx.expect(after is not None and before is not None and after.raw == before.raw,
               "F is as before the refusals (the queue still full, no more)",
               observed=show(after), expected=show(before), rule="10.1.queue.cont-buffer")
    answers(ctx, link.send("G"), "0", "G runs the queue", rule="10.1.queue.cont-buffer")
    # the host's retry: each refused vector is sent again until the unit takes it
    for kind, d in (("C", REFUSED_C), ("L", REFUSED_L)):
        r = link.poll(kind + vector(ctx, *d), lambda r: r.code != 1, 120)
        code(ctx, r, 0, f"{kind}{vector(ctx, *d)} sent again is taken once there is room",
             rule="5.code.queue-full")
    r = link.poll("L" + vector(ctx, 0), lambda r: r.code != 1, 30)
    ctx.require(r is not None and r.code == 0, "the queue did not run out within 30 s")
    drift = sum(1 if i % 2 == 0 else -1 for i in range(ctx.profile.buffer))
    moved = [drift, REFUSED_C[1], REFUSED_L[2]]
    expected = None if start is None else [s + m * step_factor(ctx)
                                           for s, m in zip(start, moved, strict=True)]
    ctx.expect(position(ctx) == expected,
               "every queued vector ran once, and each refused one only once taken",
               observed=position(ctx), expected=expected,
               rule="4.response.failed-not-executed")


#: packets that fail, each with a B member that must not be set: (members, *E's n, answer)
FAILING = (
    (["B10", "C0,50,0", "C0,50,0"], 4, "2,3"),       # count mismatch
    (["B20", "C0,50,0", "V100"], 3, "4,3"),          # a member that may not be one
    (["B30", "B1", "C0,50,0"], 3, "5,3"),            # a member out of range
)


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
    ctx.expect(position(ctx) == start, "no C member moved", observed=position(ctx),
               expected=start, rule="7.packet.all-or-nothing")
    code(ctx, link.send("L" + vector(ctx, 0)), 0, "nothing was queued: L0,0,0 → 0 at once",
         rule="7.packet.all-or-nothing")
    # B is the junction's rate: at the reset B two C pass their junction at speed, at
    # B10..B30 they would all but stop there
    Probe(ctx, "the junction at the reset B after the failed packets",
          "7.packet.all-or-nothing").script(["A5", "V2000", "C700,0,0", "C700,0,0", 1.0])
