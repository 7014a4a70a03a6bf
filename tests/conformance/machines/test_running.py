"""How long the vectors a machine had the unit take may still run: counted from the
frames and their answers, and a wait split into the unit's motion and the suite's own."""

from __future__ import annotations

import pytest

from conformance.link.account import Spent
from conformance.link.framing import parse_response
from conformance.machines.running import Running
from conformance.targets import parse_target
from gve_fixtures.protocol import SECOND

TAKEN, HALTED = parse_response(b"0\r", summed=False), parse_response(b"8\r", summed=False)


def running() -> Running:
    return Running(parse_target("emu:GVE84-100").session.open_link(), 1000, 20_000.0)


def test_a_vector_from_rest_runs_its_steps_at_the_speed_and_one_ramp():
    r = running()
    r.took(500, TAKEN)
    assert r.left() == round(0.55 * SECOND)
    r.took(500, TAKEN)                           # a C behind it joins without a stop
    assert r.left() == round(1.05 * SECOND)


@pytest.mark.parametrize("answer", [HALTED, parse_response(b"1\r", summed=False), None])
def test_a_vector_refused_unanswered_or_held_by_inta_runs_nothing(answer):
    r = running()
    r.took(500, answer)
    assert r.left() == 0


def test_halted_vectors_wait_for_g_and_a_deleted_one_never_runs():
    r = running()
    r.took(500, TAKEN)
    r.halted()
    assert r.left() == 0
    r.resumed()
    assert r.left() == round(0.55 * SECOND)
    r.halted()
    r.dropped()
    r.resumed()
    assert r.left() == 0


def test_a_wait_is_motion_while_they_may_run_and_the_suites_own_after():
    r = running()
    r.took(500, TAKEN)
    before = dict(r.link.account.booked)
    r.wait(1.0)
    after = r.link.account.booked
    assert after[Spent.MOTION] - before[Spent.MOTION] == pytest.approx(0.55)
    assert after[Spent.WAITS] - before[Spent.WAITS] == pytest.approx(0.45)
    r.at_rest()
    assert r.left() == 0
