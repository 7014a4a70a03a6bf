"""The relay's record of its own lateness: the checks do not hold against a host what
the relay's stalls did (recording.STALL_NS)."""

from __future__ import annotations

import pytest

from conformance.host import relay as relay_module
from conformance.host.line_faults import Fault, JobPoint, QueueFull
from conformance.host.played_units import load_units, open_line
from conformance.host.ports.silent import SilentPort
from conformance.host.recording import STALL_NS
from conformance.host.relay import Relay
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


class TakingPort(SilentPort):
    """A host port that keeps what the host is given."""

    def __init__(self) -> None:
        super().__init__()
        self.given = bytearray()

    def write(self, data: bytes) -> int:
        self.given += data
        return len(data)


def test_a_repeat_after_a_full_queue_shows_the_host_s_frame_and_the_1_it_got():
    # the fault hands the unit F in the vector's place; `>` must still show what a
    # full queue's unit would: the vector as the host sent it, and 1
    units = load_units(["GVE84-100"])
    line, port = open_line(units, 38400), TakingPort()
    relay = Relay(port, line, line_views(units), QueueFull(JobPoint(b"", 0)), 38400)
    try:
        for frame in (b"!0L10,0,0\r", b"!0>\r", b"!0@\r", b"!0>\r"):
            port.given.clear()
            relay.take_host(frame, relay_module.now())
            for _ in range(100):                  # until the answer is due (its bytes' time)
                relay.step(0.05)
                if port.given.endswith(b"\r") and port.given.count(b"\r") >= \
                        (2 if frame == b"!0>\r" else 1):
                    break
            if frame == b"!0L10,0,0\r":
                assert port.given == b"1\r"
            elif frame == b"!0>\r":
                assert port.given == b"!0L10,0,0\r1\r"    # `@` is not remembered
    finally:
        line.close()
        port.close()
