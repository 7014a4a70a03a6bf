"""The unit's liveness as the link tells it each exchange: frames the manuals answer with
nothing (a packet's start and members, spec 7) are no silence, a `>` answered in one
line is an answer (spec 8: `0` with no history), and a unit that truly stopped answering
is given up after the same frames once a frame that must be answered goes unanswered."""

from __future__ import annotations

import pytest

from conformance.link.link import Link
from conformance.link.liveness import SILENCE_LIMIT, TargetNotResponding
from conformance.protocol.wire import frame
from conformance.targets import parse_target

#: what diff drew: a `>` with a wrong checksum (awaiting its two lines), then a packet
#: whose members are a `B`, a breaker the unit may keep as a member, and a `C`
STEPS = [">", "*S", "B100000", "VL312,3588,131679", "C86,0,196"]


class _Mute:
    """The emulator's port, its answers swallowed: a unit that stopped answering."""

    def __init__(self, port) -> None:
        self._port = port

    def __getattr__(self, name: str):
        return getattr(self._port, name)

    @property
    def in_waiting(self) -> int:
        return 0

    def read(self, n: int = 1) -> bytes:
        self._port.read(self._port.in_waiting)
        return b""

    def read_until(self, _end: bytes = b"\r") -> bytes:
        self._port.read(self._port.in_waiting)
        return b""


def _steps(link: Link) -> None:
    """The steps as the diff sends them: raw frames, each answer read as it awaits."""
    for body in STEPS:
        if body == ">":
            link.send_raw(frame(">", link.address, "00"))
            link.read_response(lines=2)
        elif body == "*S":
            link.send_raw(frame("*S", link.address))
            link.wait(link.byte_seconds(64))
        else:
            link.send_raw(frame(body, link.address))
            link.read_response()


def _link() -> Link:
    return parse_target("emu:GVE84-100").open_link()


def test_a_repeat_in_one_line_then_a_packet_is_no_silence():
    link = _link()
    for _ in range(3):
        _steps(link)
        assert link.guard.liveness.silences == 0          # `>` refused in one line: 4
    assert link.guard.responding


def test_a_repeat_answered_in_one_line_is_an_answer():
    link = _link()
    link.send_raw(frame(">", link.address))
    r = link.read_response(lines=2)
    assert r is not None and r.code is None and r.raw == b"0\r"     # not the two lines
    assert link.guard.liveness.silences == 0 and link.guard.liveness.garbage == ""


def test_a_unit_that_stopped_answering_is_given_up_after_the_same_steps():
    """Silent inside a packet, a unit may be keeping frames as members (spec 7 [D]); an
    `*E` is answered whatever the packet, so its silence counts, as the `>`'s did."""
    link = _link()
    link.port = _Mute(link.port)
    _steps(link)
    assert link.guard.liveness.silences == 1                # the `>`
    with pytest.raises(TargetNotResponding, match=f"{SILENCE_LIMIT} frames unanswered"):
        for _ in range(SILENCE_LIMIT):
            link.send("*E3")
