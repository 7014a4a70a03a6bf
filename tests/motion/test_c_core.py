"""The C core holds pushes in a batch and sends them into C together: every other call
sees the queue exactly as after those pushes one by one (as the Python twin does), a
batch longer than the buffer holds goes in whole, and a vector that does not fit the
C core's 64-bit fields is refused by its own push, leaving the held ones as they were."""

from __future__ import annotations

import numpy as np
import pytest

from emulator.motion.factory import c_available, create
from emulator.motion.interface import EMPTY_SAVE, Motion, Vector

pytestmark = pytest.mark.skipif(not c_available(), reason="the C stepper core is not built "
                                "(the emulator falls back to the Python twin)")

MS = 1_000_000
LATER = 150 * MS          # the first vector is moving
LONG = 5_000 * MS         # every vector has ended

#: every call of the Motion interface but push, as a function of a core and an instant
CALLS = {
    "advance": lambda m, t: m.advance(t + LONG),
    "now": lambda m, t: m.now,
    "next_event": lambda m, t: m.next_event(),
    "drain_instant": lambda m, t: m.drain_instant(),
    "position": lambda m, t: m.position(t + LATER),
    "physical": lambda m, t: m.physical(t + LATER),
    "excursion": lambda m, t: m.excursion(t + LATER),
    "flags": lambda m, t: m.flags(t + LATER),
    "queued": lambda m, t: m.queued(t + LATER),
    "instant_of_position": lambda m, t: m.instant_of_position(0, 500),
    "pulses": lambda m, t: [a.tolist() for a in m.pulses(0, t + LATER)],
    "halt": lambda m, t: m.halt(t + LATER),
    "resume": lambda m, t: m.resume(t + LONG),
    "clear": lambda m, t: m.clear(t + LATER),
    "keep": lambda m, t: m.keep(t + LATER),
    "restore": lambda m, t: m.restore(EMPTY_SAVE, t + LATER),
    "set_position": lambda m, t: m.set_position(1, 77, t + LATER),
    "jump": lambda m, t: m.jump(0, -5, t + LATER),
    "set_velocity": lambda m, t: m.set_velocity(3_000, t + LATER),
    "scale_velocity": lambda m, t: m.scale_velocity(15, 16, t + LATER, accel=True),
    "set_multiplier": lambda m, t: m.set_multiplier(40, t + LATER),
}


def vector(i: int, continuous: bool = True) -> Vector:
    return Vector((800 + i, -300, 40 * i, 0), continuous, 5_000, 200_000, 2_000, 10, 2 * MS,
                  False, (8_000,) * 4)


def observe(m: Motion, t: int):
    return (m.position(t), m.physical(t), m.excursion(t), m.flags(t), m.queued(t),
            m.next_event(), m.drain_instant(), m.now)


def test_the_calls_are_the_interfaces():
    public = {name for name in dir(Motion) if not name.startswith("_")}
    assert public - {"push"} == set(CALLS)


@pytest.mark.parametrize("name", sorted(CALLS))
def test_every_call_sees_the_pushes_before_it(name):
    cores = [create(4, 10_000, stepper=s) for s in ("python", "c")]
    answers = []
    for m in cores:
        for i in range(5):
            m.push(vector(i, continuous=i != 2), i * MS)
        answers.append(CALLS[name](m, 5 * MS))
    assert answers[0] == answers[1]
    for t in (6 * MS, 400 * MS, 2 * LONG):
        assert observe(cores[0], t) == observe(cores[1], t)
    trains = [[a.tolist() for a in m.pulses(0, 2 * LONG)] for m in cores]
    assert trains[0] == trains[1]


def test_a_batch_longer_than_the_buffer_goes_in_whole():
    from emulator.motion.c_core import BATCH
    py, c = (create(4, 10_000, stepper=s) for s in ("python", "c"))
    for m in (py, c):
        for i in range(2 * BATCH + 7):
            m.push(vector(i % 50), i)
    assert c.queued(3 * BATCH) == py.queued(3 * BATCH) == 2 * BATCH + 7
    assert c.drain_instant() == py.drain_instant()
    end = c.drain_instant() + 1
    assert all(np.array_equal(a, b) for a, b in zip(c.pulses(0, end), py.pulses(0, end),
                                                    strict=True))


def test_a_vector_beyond_64_bits_is_refused_by_its_own_push():
    c = create(4, 10_000, stepper="c")
    c.push(vector(1), 0)
    with pytest.raises(OverflowError):
        c.push(Vector((2**70, 0, 0, 0), True, 5_000, 200_000, 2_000, 10, 0, False,
                      (8_000,) * 4), 1)
    c.push(vector(2), 2)
    assert c.queued(3) == 2
    assert c.keep(3).entries[0][0] == vector(1)
