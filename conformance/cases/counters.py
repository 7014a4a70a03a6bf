"""Section 10: the position counters over their whole range. `N<axis> n` sets a counter
without any motion, so the ends of ±2147483647 are reached on any unit whatever its
envelope; a short move that ends on an end shows the counters count there too."""

from __future__ import annotations

from conformance.case import CaseContext, case
from conformance.cases._kit import code, position, setup, step_factor, vector

#: steps of the moves that end on a counter's end (well inside the directed envelope)
RUN_IN = 100


def _set(ctx: CaseContext, axis: str, value: int, want: int, rule: str) -> None:
    code(ctx, ctx.link.send(f"N{axis}{value}"), want, f"N{axis}{value} → {want}", rule=rule)


def _reads(ctx: CaseContext, expected: list[int], what: str) -> None:
    got = position(ctx)
    ctx.expect(got == expected, what, observed=got, expected=expected, rule="10.cmd.positions")


def _settle(ctx: CaseContext) -> None:
    r = ctx.link.poll("L" + vector(ctx, 0), lambda r: r.code != 1, 30)
    ctx.require(r is not None and r.code == 0, "the moves did not end within 30 s")


@case("10.commands.counter-range-ends", requires=("NX",),
      rules=("10.cmd.set-axis", "10.cmd.positions", "5.code.range"))
def range_ends(ctx: CaseContext) -> None:
    p = ctx.profile
    lo, hi = p.ranges["position"].lo, p.ranges["position"].hi
    shown = p.axes[:3]                       # PF reads X Y Z (the GVE114's A is not shown)
    scale = step_factor(ctx)
    start = position(ctx)
    ctx.require(start is not None, "PF did not answer with positions")
    # first the moves, each ending on an end and coming back: read while the vector may
    # still run as far as the guard knows (PF until it shows the end), so that a unit
    # whose counters wrap is not taken for one whose axes went elsewhere, and the axes
    # come back whatever it reads
    near = [hi - RUN_IN, lo + RUN_IN, hi - RUN_IN]
    for axis, value in zip(shown, near, strict=True):
        _set(ctx, axis, value, 0, "10.cmd.set-axis")
    for d, there, what in (((RUN_IN, -RUN_IN, RUN_IN), [hi, lo, hi], "a move counted up to "
                            "the ends"), ((-RUN_IN, RUN_IN, -RUN_IN), near, "and back")):
        setup(ctx, "L" + vector(ctx, *d))
        want = [v * scale for v in there]
        r = ctx.link.poll("PF", lambda r, want=want: r.code == 0 and r.values == [
            str(v) for v in want], 5.0, every=0.02)
        got = r.decs() if r is not None else position(ctx)
        ctx.expect(r is not None, what, observed=got, expected=want, rule="10.cmd.positions")
    _settle(ctx)
    # then each axis at each end, its neighbours at the other: every reading tells them apart
    for ends in ((hi, lo, hi), (lo, hi, lo)):
        for axis, value in zip(shown, ends, strict=True):
            _set(ctx, axis, value, 0, "10.cmd.set-axis")
        _reads(ctx, [v * scale for v in ends], f"PF reads the counters at {ends}")
        for axis, value in zip(shown, ends, strict=True):
            beyond = value + (1 if value > 0 else -1)
            _set(ctx, axis, beyond, 5, "5.code.range")
        _reads(ctx, [v * scale for v in ends], "the refused N<axis> changed no counter")
    if "NA" in p.commands:                   # the A counter: set and refused, not read
        for value, want in ((hi, 0), (hi + 1, 5), (lo, 0), (lo - 1, 5), (0, 0)):
            _set(ctx, "A", value, want, "10.cmd.set-axis" if want == 0 else "5.code.range")
    # back where the case began
    for axis, value in zip(shown, start, strict=True):
        _set(ctx, axis, value // scale, 0, "10.cmd.set-axis")
    _reads(ctx, start, "the counters are back where the case found them")
