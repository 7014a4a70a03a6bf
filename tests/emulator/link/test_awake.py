"""Whether the co-simulation server stays awake for its driver's next command
(emulator/link/awake.py): only while the machine has a processor to spare, the idle time
read from the machine and the server's own awake time counted."""

from __future__ import annotations

import pytest

from emulator.link import awake as awake_module
from emulator.link.awake import Awake, idle_seconds


class Machine:
    """A clock and the idle processor seconds a machine reports, both moved by hand."""

    def __init__(self, idle: float | None = 0.0) -> None:
        self.now = 0.0
        self.idle_total = idle

    def clock(self) -> float:
        return self.now

    def idle(self) -> float | None:
        return self.idle_total

    def passes(self, seconds: float, idle_processors: float) -> None:
        self.now += seconds
        if self.idle_total is not None:
            self.idle_total += seconds * idle_processors


def test_it_sleeps_at_once_until_the_machine_has_been_read():
    machine = Machine()
    a = Awake(machine.idle, machine.clock)
    assert a.window == 0.0
    machine.passes(awake_module.EVERY / 2, 2.0)
    a.waited(0.0)
    assert a.window == 0.0, "read again only every EVERY seconds"


@pytest.mark.parametrize(("idle", "awake", "opens"), [
    (1.0, 0.0, True),           # a processor left idle
    (0.0, 0.0, False),          # a loaded machine
    (0.1, 0.0, False),          # not enough to spare
    (0.0, 0.6, True),           # its own time awake was spare too
])
def test_the_window_opens_only_on_a_processor_to_spare(idle, awake, opens):
    machine = Machine()
    a = Awake(machine.idle, machine.clock)
    machine.passes(awake_module.EVERY, idle)
    a.waited(awake * awake_module.EVERY)
    assert a.window == (awake_module.SECONDS if opens else 0.0)


def test_it_closes_again_once_the_machine_is_busy():
    machine = Machine()
    a = Awake(machine.idle, machine.clock)
    machine.passes(awake_module.EVERY, 1.0)
    a.waited(0.0)
    assert a.window == awake_module.SECONDS
    machine.passes(awake_module.EVERY, 0.0)
    a.waited(0.0)
    assert a.window == 0.0


def test_a_machine_whose_idle_time_cannot_be_read_never_keeps_it_awake():
    machine = Machine(idle=None)
    a = Awake(machine.idle, machine.clock)
    machine.passes(awake_module.EVERY, 2.0)
    a.waited(awake_module.EVERY)
    assert a.window == 0.0


def test_the_machine_s_idle_time_is_read_as_seconds_that_never_go_back():
    first = idle_seconds()
    second = idle_seconds()
    assert first is None or (0 <= first <= second)
