"""The error-code machine's waits: while the vectors the unit took may run (at the speed
set, ramps at the reset acceleration), a wait is the unit's motion in the run's time
account; the rest, and a wait with nothing under way, the suite's own."""

from __future__ import annotations

import pytest

from conformance.case import settings as settings_profiles
from conformance.case.context import CaseContext
from conformance.link.account import Spent
from conformance.machines.errors import ErrorMachine
from conformance.run.selection import select
from conformance.targets import parse_target


def machine() -> ErrorMachine:
    (case,) = select(["5.machine.error-codes"])
    target = parse_target("emu:GVE84-100")
    ctx = CaseContext(case, target.profile, target.info, settings_profiles.get("ci"),
                      target.session.open_link)
    return ErrorMachine(ctx)


def booked(m: ErrorMachine) -> dict[Spent, float]:
    return dict(m.link.account.booked)


def test_a_wait_with_nothing_under_way_is_the_suites_own():
    m = machine()
    before = booked(m)
    m.wait(0.3)
    after = booked(m)
    assert after[Spent.WAITS] - before[Spent.WAITS] == pytest.approx(0.3)
    assert after[Spent.MOTION] == before[Spent.MOTION]


def test_a_wait_while_a_vector_runs_is_motion_up_to_its_time():
    m = machine()
    m.motion(500)                        # 0.5 s at V1000 and 0.05 s of ramps at A20
    before = booked(m)
    m.wait(1.5)
    after = booked(m)
    motion = after[Spent.MOTION] - before[Spent.MOTION]
    assert 0.5 < motion <= 0.55
    assert after[Spent.WAITS] - before[Spent.WAITS] == pytest.approx(1.5 - motion)
    assert m.observe()[0] is False       # the vector had ended within its time


def test_a_halted_vector_is_no_motion_until_g_resumes_it():
    m = machine()
    m.motion(1500)
    m.halt()
    before = booked(m)
    m.wait(0.3)
    assert booked(m)[Spent.MOTION] == before[Spent.MOTION]
    m.probe("G")
    before = booked(m)
    m.wait(0.3)
    assert booked(m)[Spent.MOTION] - before[Spent.MOTION] == pytest.approx(0.3)
