"""The relay's record of its own lateness: the checks do not hold against a host what
the relay's stalls did (recording.STALL_NS)."""

from __future__ import annotations

import pytest

from conformance.host import relay as relay_module
from conformance.host.line_faults import Fault
from conformance.host.ports.silent import SilentPort
from conformance.host.recording import STALL_NS
from conformance.host.relay import Relay
from conformance.host.units import load_units, open_line
from conformance.host.unitview import line_views


@pytest.fixture
def clock(monkeypatch):
    t = [10**12]
    monkeypatch.setattr(relay_module, "now", lambda: t[0])
    return t


def test_a_turn_that_starts_late_is_a_stall(clock):
    units = load_units(["GVE84-100"])
    line, port = open_line(units, 38400), SilentPort()
    relay = Relay(port, line, line_views(units), Fault(), 38400)
    try:
        relay.step(0)
        ended = clock[0]
        clock[0] += STALL_NS // 2                 # a usual pause between turns
        relay.step(0)
        assert relay.rec.stalls == []
        clock[0] += 300 * 1_000_000               # the thread waited 300 ms for its turn
        relay.step(0)
        assert relay.rec.stalls == [(ended + STALL_NS // 2, clock[0])]
    finally:
        line.close()
        port.close()
