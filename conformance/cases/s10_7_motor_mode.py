"""Spec section 10.7, GVE54 motor mode `M`: the cases that check it.

Micro-stepping and current of the GVE54."""

from __future__ import annotations

from conformance.case.context import CaseContext, case
from conformance.cases._kit import (
    answers,
    code,
    finished,
    measured_case,
    position,
    setup,
    show,
    vector,
)
from conformance.motion.probe import Probe
from gve_fixtures.protocol import ErrorCode

#: the move each micro-step mode makes (commanded steps): a factor of another mode ends
#: elsewhere on every axis
MODE_MOVE = (60, -30, 15)


def _rest(ctx: CaseContext) -> None:
    r = finished(ctx, 30, lambda r: r.code != ErrorCode.QUEUE_FULL)
    ctx.require(r is not None and r.ok, "the move did not end within 30 s")


# id -> (rules (the first judges the readings), commands it requires, families, scenario)
SCENARIOS: dict[str, tuple[tuple[str, ...], tuple[str, ...], tuple[str, ...], list]] = {
    # GVE54: rates and vectors in commanded steps, positions in sixteenths (10.7)
    "10.7.measured.microstep-rates": (
        ("10.7.motor.rates-scaled", "10.2.motion.gve54-units"), ("M",), (),
        ["M4", "A2", "V500", "L300,-100,0", 0.35, [300, -100, 0], "MF", "L400,0,0", 0.3]),
}


for _id, (_rules, _requires, _families, _scenario) in SCENARIOS.items():
    measured_case(_id, _rules, _requires, _families, _scenario)


@case("10.7.microstep.each-mode", requires=("M",), timing=True,
      rules=("10.7.motor.modes", "10.7.motor.rates-scaled", "10.2.motion.gve54-units"))
def each_mode(ctx: CaseContext) -> None:
    """Every micro-step mode with the same move: where it ends (exact, in sixteenths) and
    how it gets there (measured, the rates scaled by the mode's factor)."""
    ms = ctx.profile.microstep
    start = position(ctx)
    ctx.require(start is not None, "PF did not answer with positions")
    for mode, factor in ms.factors.items():
        setup(ctx, f"M{mode}")
        setup(ctx, "L" + vector(ctx, *MODE_MOVE))
        _rest(ctx)
        want = [s + factor * d for s, d in zip(start, MODE_MOVE, strict=True)]
        ctx.expect_equal(position(ctx), want, f"M{mode}: L{vector(ctx, *MODE_MOVE)} ends "
                         f"{factor} sixteenths a step on", rule="10.7.motor.modes")
        setup(ctx, "L" + vector(ctx, *(-d for d in MODE_MOVE)))
        _rest(ctx)
    setup(ctx, f"M{ms.reset_mode}")
    for mode in ms.factors:
        Probe(ctx, f"the move in M{mode}", "10.7.motor.rates-scaled").script(
            [f"M{mode}", "A2", "V400", "L" + vector(ctx, *MODE_MOVE), 0.5])
        setup(ctx, "L" + vector(ctx, *(-d for d in MODE_MOVE)))
        _rest(ctx)
        setup(ctx, f"M{ms.reset_mode}")
    ctx.expect_equal(position(ctx), start, "the axes are back where the case found them",
                     rule="10.7.motor.modes")


@case("10.7.microstep.positions-in-sixteenths",
      rules=("10.2.motion.gve54-units", "10.7.motor.modes"),
      requires=("M",))
def microstep(ctx: CaseContext) -> None:
    """GVE54 positions are in 1/16 steps: M4, L100,100,100 → 400."""
    link = ctx.link
    setup(ctx, "M4")
    setup(ctx, "L100,100,100")
    finished(ctx, 60)
    answers(ctx, link.send("PF"), "0,400,400,400", "PF after M4 and L100,100,100",
            rule="10.2.motion.gve54-units")
    # the manual lists the modes; another letter may be a syntax error or a parameter
    # out of range: both readings are allowed, taking it is not
    r = link.send("MQ")
    ctx.expect(r is not None and r.code in (ErrorCode.SYNTAX, ErrorCode.RANGE),
               "an unknown mode is refused (4 or 5)", observed=show(r), expected="4 or 5",
               rule="10.7.motor.modes")


@case("10.7.motor.modes-while-moving", requires=("M",),
      rules=("10.7.motor.busy", "10.7.motor.any-position", "5.moving.definition"))
def motor_busy(ctx: CaseContext) -> None:
    link = ctx.link
    setup(ctx, "V5000")
    setup(ctx, "L1001,500,399")
    code(ctx, link.send("M4"), ErrorCode.BUSY, "M while moving → 7", rule="10.7.motor.busy")
    finished(ctx, 10)
    ctx.expect_equal(position(ctx), [1001, 500, 399], "in MF the counters count the steps",
                     rule="10.7.motor.any-position")
    answers(ctx, link.send("M2"), "0", "a coarser mode at a position not divisible by 8",
            rule="10.7.motor.any-position")
    setup(ctx, "MF")
    setup(ctx, "L-1,0,1")
    finished(ctx, 10)
    ctx.expect_equal(position(ctx), [1000, 500, 400], "the manual's example: L-1,0,1",
                     rule="10.7.motor.any-position")
    answers(ctx, link.send("M4"), "0", "then M4", rule="10.7.motor.any-position")
    # halted, the vector's rest held (RUN = 1): nothing moves, so M is taken in our
    # reading of "za chodu" (a unit may refuse it with 7 while RUN = 1)
    setup(ctx, "L100,0,0")
    setup(ctx, "H", expect="8")
    code(ctx, link.send("MF"), ErrorCode.OK, "M after H with the vector halted", inta=True,
         rule="5.moving.definition")
    setup(ctx, "D")


#: the commands acting on the motors that each micro-step mode is combined with (the
#: catalogue's vectors, stops, resumes, exchanges, the queue's emptying and saving, the
#: counters' zeroing): each a scenario from rest back to rest whose end is exact in any
#: mode, named by the commands it combines, as (frames and waits, the move it makes in
#: commanded steps). `V500` first: a 200-step vector runs 0.4 s, halted 0.1 s in.
COMBINED: dict[str, tuple[list, tuple[int, int, int]]] = {
    "L": (["L60,-30,15"], (60, -30, 15)),
    "C": (["C60,-30,15", "C60,-30,15"], (120, -60, 30)),
    "H, G": (["V500", "L200,0,0", 0.1, "H", "G"], (200, 0, 0)),
    "SW6": (["V500", "L200,0,0", 0.1, "SW6,80", 0.1, "SW6,00"], (200, 0, 0)),
    "H, K, R, G": (["V500", "C200,0,0", 0.1, "H", "K", "L0,0,-10", "rest", "L0,0,10",
                    "rest", "R", "G"], (200, 0, 0)),
    "XU, XD, XA": (["V500", "C200,0,0", "C100,0,0", 0.05, "XU", 0.05, "XD", 0.05, "V800",
                    "XA"], (300, 0, 0)),
}


def _settled(ctx: CaseContext, what: str) -> list[int]:
    _rest(ctx)
    here = position(ctx)
    ctx.require(here is not None, f"{what}: PF did not answer with positions")
    return here


@case("10.7.microstep.with-motion-commands", requires=("M",), timing=True,
      rules=("10.7.motor.modes", "10.cmd.positions", "10.4.delete", "10.cmd.zero"))
def with_motion_commands(ctx: CaseContext) -> None:
    """Every micro-step mode with every command that acts on the motors: where each
    scenario ends (exact, in sixteenths: the mode's factor times its move), P and PF
    alike; D after H leaves the position where H stopped, N zeroes it in any mode."""
    ms, link = ctx.profile.microstep, ctx.link
    for mode, factor in ms.factors.items():
        for name, (scenario, move) in COMBINED.items():
            start = _settled(ctx, name)
            setup(ctx, f"M{mode}")
            for step in scenario:
                if step == "rest":
                    _rest(ctx)
                elif isinstance(step, str):
                    r = link.send(step)
                    ctx.require(r is not None and r.code is not None and r.code & 7 == 0,
                                f"M{mode}, {name}: {step} answered {show(r)}")
                else:
                    link.wait(step)
            want = [s + factor * d for s, d in zip(start, move, strict=True)]
            got = _settled(ctx, f"M{mode}, {name}")
            ctx.expect(got == want, f"M{mode} with {name}: ends {factor} sixteenths a "
                       "commanded step on", observed=got, expected=want,
                       rule="10.7.motor.modes")
            r = link.send("P")
            ctx.expect(r is not None and r.ok and r.values == [str(v) for v in got[:2]],
                       f"M{mode} with {name}: P reads PF's X and Y", observed=show(r),
                       expected="0,%d,%d" % tuple(got[:2]), rule="10.cmd.positions")
            setup(ctx, "V1000")
            setup(ctx, "L" + vector(ctx, *(-d for d in move)))
        before = _settled(ctx, f"M{mode}, D")
        setup(ctx, "V500")
        setup(ctx, "C200,0,0")
        link.wait(0.1)
        setup(ctx, "H", expect="8")
        stopped = position(ctx)
        setup(ctx, "D")
        ctx.expect_equal(position(ctx), stopped, f"M{mode}: D after H leaves the position",
                         rule="10.4.delete")
        setup(ctx, "N")
        setup(ctx, "V1000")
        setup(ctx, "L" + vector(ctx, *MODE_MOVE))
        got = _settled(ctx, f"M{mode}, N")
        want = [factor * d for d in MODE_MOVE]
        ctx.expect(got == want, f"M{mode}: after N, L{vector(ctx, *MODE_MOVE)} reads "
                   f"{factor} sixteenths a step from 0", observed=got, expected=want,
                   rule="10.cmd.zero")
        setup(ctx, f"M{ms.reset_mode}")
        ctx.require(stopped is not None, f"M{mode}: PF did not answer after H")
        # in sixteenths (the reset mode's step): back where the C began
        back = [b - s - g for b, s, g in zip(before, stopped, got, strict=True)]
        setup(ctx, "L" + vector(ctx, *back))
        _rest(ctx)
        setup(ctx, "N")


@case("10.7.microstep.current-apart", requires=("M",), rules=("10.7.motor.modes",))
def current_apart(ctx: CaseContext) -> None:
    """The current (MU, MD) and the step division (M2..MF) are two settings: a current set
    after a mode leaves the mode, and a step goes its factor of sixteenths."""
    ms = ctx.profile.microstep
    for mode, factor in ms.factors.items():
        if mode == ms.reset_mode:
            continue
        for current in ms.currents:
            start = _settled(ctx, f"M{mode}, M{current}")
            setup(ctx, f"M{mode}")
            setup(ctx, f"M{current}")
            setup(ctx, "L" + vector(ctx, *MODE_MOVE))
            got = _settled(ctx, f"M{mode}, M{current}")
            want = [s + factor * d for s, d in zip(start, MODE_MOVE, strict=True)]
            ctx.expect(got == want, f"M{mode} then M{current}: a step is still {factor} "
                       "sixteenths", observed=got, expected=want, rule="10.7.motor.modes")
            setup(ctx, "L" + vector(ctx, *(-d for d in MODE_MOVE)))
    _rest(ctx)
    setup(ctx, f"M{ms.reset_mode}")
    setup(ctx, f"M{ms.reset_current}")
