"""Sections 9, 10, 10.2, 10.4, 10.7: the motion measured. Each case runs a short scenario,
reads ``PF`` at known instants and judges every reading against the suite's own model of
spec 10.2 (conformance/motion), with the tolerance printed in each check: zero on the
embedded emulator's virtual clock (and not printed); on serial and TCP targets the window
in which the unit processed each frame, widened by the line's band (from the round trip
measured at the session's start and the scenario's own, conformance/link/line_band.py),
and one step: a position read at rest after an override, a HALT or a micro-step change is
judged with what the event's instant so widened can change (``±1.8 ms line, ±7 steps``).

A scenario is a list: a frame to send, seconds to sample ``PF`` for (every 50 ms, or a
pair: seconds and how often), or a position (in commanded steps) to poll ``PF`` until.
"""

from __future__ import annotations

from conformance.case import CaseContext, case
from conformance.cases._kit import fresh_reset
from conformance.motion.probe import Probe

# id -> (rules (the first judges the readings), commands it requires, families, scenario)
SCENARIOS: dict[str, tuple[tuple[str, ...], tuple[str, ...], tuple[str, ...], list]] = {
    # the dominant axis cruises at V; P/PF are the counts at the instant (10.2)
    "10.2.measured.cruise-at-v": (
        ("10.2.motion.dominant-rate", "10.2.motion.positions-now", "10.2.motion.step-placement"),
        (), (), ["A10000", "V3000", "L600,-200,0", 0.25]),
    # VK: the speed along the path, the dominant rate V·n/|d| (10.2)
    "10.2.measured.path-rate": (
        ("10.2.motion.path-rate", "10.cmd.vk-vn"), ("VK",), (),
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
    # no dwell between continuous vectors (10.2; M84 12.5.2)
    "10.2.measured.no-dwell-continuous": (
        ("10.2.motion.no-dwell-continuous",), (), (),
        ["T24", "A10000", "V2000", "C100,0,0", "C100,0,0", 0.12]),
    # the junction: a C followed by a C exits at B (10.2)
    "10.2.measured.junction": (
        ("10.2.motion.junction",), (), (),
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
    # modal parameters are captured with each vector when it is accepted (10.1)
    "10.1.measured.captured": (
        ("10.1.queue.captured",), (), (),
        ["A10000", "V1000", "C400,0,0", "V3000", "A1", "C400,0,0", 0.9]),
    # XM acts at once on the running and the queued vectors (10)
    "10.cmd.measured.override": (
        ("10.cmd.override",), ("XM",), (),
        ["V1000", "C700,0,0", "C700,0,0", 0.2, "XM200", 0.45, "XM50", 0.2]),
    # XA: the running and queued vectors take the modal V (10)
    "10.cmd.measured.exchange-xa": (
        ("10.cmd.exchange-velocity", "10.1.queue.captured"), (), (),
        ["V1000", "C600,0,0", "C600,0,0", 0.2, "V3000", 0.1, "XA", 0.35]),
    # XU / XD: ×17/16, ×15/16 (10)
    "10.cmd.measured.exchange-xu-xd": (
        ("10.cmd.exchange-velocity",), (), (),
        ["A10000", "V1600", "C1200,0,0", 0.15, "XU", 0.15, "XD", 0.15, "XD", 0.15]),
    # GVE54: XA/XU/XD also set or scale the acceleration (10)
    "10.cmd.measured.exchange-accel": (
        ("10.cmd.exchange-accel-gve54",), (), ("GVE54",),
        ["A2", "V3000", "C1500,0,0", 0.1, "A10", "XA", 0.2, "XD", 0.2]),
    # H brakes on the ramp and answers at rest; G resumes from rest (10.4)
    "10.4.measured.halt-ramp": (
        ("10.4.halt.ramp", "10.4.go.resume"), (), (),
        ["A3", "V1500", "C1500,0,0", 0.6, "H", 0.05, "G", 0.8]),
    # the HALT ramp runs on into the following vectors (10.4)
    "10.4.measured.halt-through-vectors": (
        ("10.4.halt.through-vectors",), (), (),
        ["A2", "V2000", "C500,0,0", "C500,0,0", "C500,0,0", 0.55, "H", 0.05, "G", 0.6]),
    # G resumes from the exact step, accelerating from rest (10.4)
    "10.4.measured.go-from-rest": (
        ("10.4.go.resume",), (), (),
        ["A2", "V1200", "L1400,0,0", 0.5, "H", 0.05, "G", 0.3]),
    # GVE54: rates and vectors in commanded steps, positions in sixteenths (10.7)
    "10.7.measured.microstep-rates": (
        ("10.7.motor.rates-scaled", "10.2.motion.gve54-units"), ("M",), (),
        ["M4", "A2", "V500", "L300,-100,0", 0.35, [300, -100, 0], "MF", "L400,0,0", 0.3]),
}


def _fill(step, ctx: CaseContext):
    """The scenario's placeholders: ``{max}`` the variant's maximum rate, ``{max10}`` a
    tenth of it, ``{xm}`` an override doubling V where the profile has XM."""
    if not isinstance(step, str):
        return step
    rate = ctx.profile.max_rate
    return step.format(max=rate, max10=rate // 10, xm="XM200" * ("XM" in ctx.profile.commands))


def _register(id: str, rules: tuple[str, ...], requires: tuple[str, ...],
              families: tuple[str, ...], scenario: list) -> None:
    @case(id, rules=rules, requires=requires, timing=True,
          applies=(lambda p: p.family in families) if families else None)
    def measured(ctx: CaseContext) -> None:
        Probe(ctx, id, rules[0]).script([s for s in (_fill(s, ctx) for s in scenario) if s])


for _id, (_rules, _requires, _families, _scenario) in SCENARIOS.items():
    _register(_id, _rules, _requires, _families, _scenario)


@case("9.reset.measured-defaults", rules=("9.reset.state", "9.reset.decided", "9.reset.brake"),
      timing=True)
def reset_motion(ctx: CaseContext) -> None:
    """A20, V1000 (9.reset.state); VN, XM100, VL = max, T = 5 ms (9.reset.decided); B = max:
    a junction at the full rate (9.reset.brake), each measured from the reset state."""
    fresh_reset(ctx)
    Probe(ctx, "reset A and V", "9.reset.state").script(["L500,0,0", 0.7])
    Probe(ctx, "reset VN, XM, VL, T", "9.reset.decided").script(
        ["L300,-400,0", [300, -400, 0], "L10,0,0", 0.03])
    Probe(ctx, "reset B", "9.reset.brake").script(["C-300,400,0", "C-200,0,0", 0.7])


#: a junction with B differing on both sides, each way round: (B before, B after)
JUNCTION_SIDES = ((300, 1500), (1500, 300))


@case("10.2.measured.junction-brake-sides", timing=True,
      rules=("10.2.motion.junction", "10.2.motion.junction-own-b"))
def junction_sides(ctx: CaseContext) -> None:
    """Which B governs a junction when the two C captured different ones: the ending C's
    (10.2.motion.junction-own-b [D]). Readings that fit a junction at the next C's B are
    that other reading (NON-STRICT); readings that fit neither break B itself [M]."""
    for before, after in JUNCTION_SIDES:
        name = f"B{before} before the junction, B{after} after"
        probe = Probe(ctx, name, "10.2.motion.junction")
        probe.run(["A5", "V2000", f"B{before}", "C700,0,0", f"B{after}", "C700,0,0", 1.2,
                   [1400, 0, 0]])
        probe.next_brake = True
        other = probe.fits()
        probe.next_brake = False
        if other and not probe.fits():
            probe.rule = "10.2.motion.junction-own-b"
        probe.judge()
