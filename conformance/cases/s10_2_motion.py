"""Spec section 10.2, Motion model: the cases that check it.

How a vector is stepped: rates, ramps, junctions, dwell and step placement
(`docs/motion-model.md` gives the exact arithmetic)."""

from __future__ import annotations

from conformance.case.context import CaseContext, case
from conformance.cases._kit import finished, measured_case, position, setup, vector
from conformance.motion.probe import Probe

#: a junction with B differing on both sides, each way round: (B before, B after)
JUNCTION_SIDES = ((300, 1500), (1500, 300))


# id -> (rules (the first judges the readings), commands it requires, families, scenario)
SCENARIOS: dict[str, tuple[tuple[str, ...], tuple[str, ...], tuple[str, ...], list]] = {
    # the dominant axis cruises at V; P/PF are the counts at the instant (10.2)
    "10.2.measured.cruise-at-v": (
        ("10.2.motion.dominant-rate", "10.2.motion.positions-now", "10.2.motion.step-placement"),
        (), (), ["A10000", "V3000", "L600,-200,0", 0.25]),
    # VK: the speed along the path, the dominant rate V·n/|d| (10.2)
    "10.2.measured.path-rate": (
        ("10.2.motion.path-rate", "10.cmd.vk-vn", "10.2.motion.path-accel"), ("VK",), (),
        ["A10000", "VK", "V2000", "L300,400,0", 0.3]),
    # VL caps an axis's rate (10.2)
    "10.2.measured.axis-caps": (
        ("10.2.motion.axis-caps", "10.cmd.axis-limits"), ("VL",), (),
        ["A10000", "VL500,100000,100000", "V2000", "L400,400,0", 0.9]),
    # the trapezoid: accelerate at A, cruise, decelerate (10.2)
    "10.2.measured.trapezoid": (
        ("10.2.motion.trapezoid",), (), (), ["A5", "V1500", "L600,0,0", 0.8]),
    # T: a vector from rest starts T after the previous one ended at rest (10.2)
    "10.2.measured.dwell": (
        ("10.2.motion.dwell", "10.cmd.modal"), (), (),
        ["T24", "A10000", "V5000", "L100,0,0", [100, 0, 0], "L100,0,0", (0.06, 0.005)]),
    # a C from rest, after an L has ended: it waits T as an L does, our reading [D] (10.2)
    "10.2.measured.dwell-before-c": (
        ("10.2.motion.dwell-before-c",), (), (),
        ["T24", "A10000", "V5000", "L100,0,0", [100, 0, 0], "C100,0,0", (0.06, 0.005)]),
    # no dwell between continuous vectors (10.2; M84 12.5.2)
    "10.2.measured.no-dwell-continuous": (
        ("10.2.motion.no-dwell-continuous",), (), (),
        ["T24", "A10000", "V2000", "C100,0,0", "C100,0,0", 0.12]),
    # the junction: a C followed by a C going on the same way exits at B (10.2)
    "10.2.measured.junction": (
        ("10.2.motion.junction",), (), (),
        ["A5", "B500", "V2000", "C700,0,0", "C700,0,0", 1.2]),
    # a C followed by a C reversing its axis: at B as well, our reading [D] (10.2)
    "10.2.measured.junction-reversal": (
        ("10.2.motion.junction-reversal",), (), (),
        ["A5", "B500", "V2000", "C700,0,0", "C-700,0,0", 1.2]),
    # the exit rate lets the next vector still stop within its length (10.2)
    "10.2.measured.junction-cap": (
        ("10.2.motion.junction-cap",), (), (),
        ["A1", "B5000", "V3000", "$1", "C600,0,0", "C20,0,0", 1.0]),
    # $: a short vector cruises only towards B (10.2)
    "10.2.measured.short-vector": (
        ("10.2.motion.short-vector", "10.cmd.modal"), (), (),
        ["A10000", "$1000", "B300", "V2000", "L150,0,0", 0.5]),
    # a zero-length C between two C: the next starts from rest, after T (10.2)
    "10.2.measured.zero-length-c": (
        ("10.2.motion.zero-length",), (), (), ["C0,-92,0", "C0,0,0", "C0,46,0", 0.3]),
    # the rate never exceeds the variant's maximum (10.2)
    "10.2.measured.max-rate": (
        ("10.2.motion.max-rate", "1.profile.max-rate"), (), (),
        ["A10000", "V{max}", "{xm}", "L{max10},0,0", 0.15]),
}


for _id, (_rules, _requires, _families, _scenario) in SCENARIOS.items():
    measured_case(_id, _rules, _requires, _families, _scenario)


@case("10.2.measured.junction-brake-sides", timing=True,
      rules=("10.2.motion.junction", "10.2.motion.junction-own-b"))
def junction_sides(ctx: CaseContext) -> None:
    """Which B governs a junction when the two C captured different ones: the ending C's
    (10.2.motion.junction-own-b [D]). Readings that fit a junction at the next C's B are
    that other reading (NON-STRICT); readings that fit neither break B itself [M]."""
    # the second path runs back, so that the case ends where it began (the envelope)
    for way, (before, after) in zip((1, -1), JUNCTION_SIDES, strict=True):
        name = f"B{before} before the junction, B{after} after"
        probe = Probe(ctx, name, "10.2.motion.junction")
        leg = f"C{700 * way},0,0"
        probe.run(["A5", "V2000", f"B{before}", leg, f"B{after}", leg, 1.2,
                   [1400 * way, 0, 0]])
        probe.next_brake = True
        other = probe.fits()
        probe.next_brake = False
        if other and not probe.fits():
            probe.rule = "10.2.motion.junction-own-b"
        probe.judge()


@case("10.2.motion.targets-reached",
      rules=("10.1.queue.relative", "10.2.motion.step-placement"))
def targets(ctx: CaseContext) -> None:
    setup(ctx, "V5000")
    moves = [(100, -37, 5), (-250, 40, 0), (3, 3, -3)]
    for m in moves:
        setup(ctx, "C" + vector(ctx, *m))
    finished(ctx, 60)
    expected = [sum(m[i] for m in moves) for i in range(3)]
    ctx.expect_equal(position(ctx), expected, "the sum of the vectors", rule="10.1.queue.relative")
    ctx.step_train("the step train of the three vectors")


#: a parameter's range ends measured in motion: the parameter (a key of the profile's
#: [rates]) -> (the rule its readings judge, the scenario at each end, with `{v}` for the
#: end and `{axes}` for the profile's VL components of `{v}`). The low ends move a few
#: steps (V10 moves ten steps a second); the high ones stay short.
RATE_ENDS: dict[str, tuple[str, dict[str, list]]] = {
    "V": ("10.2.motion.dominant-rate", {
        "lo": ["A10000", "V{v}", "L4,0,0", 0.45],
        "hi": ["A10000", "V{v}", "L300,0,0", [300, 0, 0]]}),
    "XM": ("10.cmd.override", {
        "lo": ["A10000", "V1000", "XM{v}", "L4,0,0", 0.45, "XM100"],
        "hi": ["A10000", "V1000", "XM{v}", "L300,0,0", [300, 0, 0], "XM100"]}),
    "VL": ("10.2.motion.axis-caps", {
        "lo": ["A10000", "V1000", "VL{axes}", "L4,0,0", 0.45]}),
    "B": ("10.2.motion.junction", {
        "lo": ["A10000", "V1000", "$1", "B{v}", "C100,0,0", "C100,0,0", 0.35],
        "hi": ["A100", "V5000", "$1", "B{v}", "C100,0,0", "C100,0,0", 0.35]}),
    "A": ("10.2.motion.trapezoid", {
        "lo": ["A{v}", "V1000", "L150,0,0", 0.5],
        "hi": ["A{v}", "V3000", "L150,0,0", [150, 0, 0]]}),
    "T": ("10.2.motion.dwell", {
        "lo": ["A10000", "V5000", "T{v}", "L50,0,0", [50, 0, 0], "L50,0,0", (0.01, 0.001)],
        "hi": ["A10000", "V5000", "T{v}", "L50,0,0", [50, 0, 0], "L50,0,0", (0.04, 0.002)]}),
    "$": ("10.2.motion.short-vector", {
        "lo": ["A10000", "V2000", "B300", "${v}", "L150,0,0", 0.2],
        "hi": ["A10000", "V2000", "B300", "${v}", "L150,0,0", 0.2]}),
}


@case("10.2.measured.range-ends", timing=True,
      rules=("10.2.motion.dominant-rate", "10.cmd.override", "10.2.motion.axis-caps",
             "10.2.motion.junction", "10.2.motion.trapezoid", "10.2.motion.dwell",
             "10.2.motion.short-vector"))
def range_ends(ctx: CaseContext) -> None:
    """Every rate, ramp, dwell and threshold of the profile's [rates] at both ends of its
    range (from the profile), the motion each gives measured against the model: a unit
    whose slowest rate is above the range's low end, or whose dwell stops short of its
    top, moves elsewhere."""
    p = ctx.profile
    for key, (rule, scenarios) in RATE_ENDS.items():
        if key not in p.ranges or key not in p.commands:
            continue
        for end, scenario in scenarios.items():
            v = getattr(p.ranges[key], end)
            steps = [s.format(v=v, axes=",".join([str(v)] * len(p.axes)))
                     if isinstance(s, str) else s for s in scenario]
            ctx.fresh_link()
            Probe(ctx, f"{key} at the {'low' if end == 'lo' else 'high'} end of its range "
                  f"({v})", rule).script(steps)
