"""A frame's walk from its sender to the target and back visits the link once and the
guard once per exchange before the write (Guard.admit) and once after the read
(Guard.book): traced with a profiler hook (sys.setprofile) that notes every call into
each module from another module."""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path

import pytest

from conformance.link import link as link_module
from conformance.link import safety as safety_module
from conformance.link.link import Link
from conformance.link.safety import Guard
from conformance.link.signals import Interrupted
from gve_fixtures.profile import load_profile


class _Port:
    """A real-time port whose unit answers every frame `0` at once."""

    timeout = None

    def __init__(self) -> None:
        self.answer = b""
        self.written = bytearray()

    @property
    def in_waiting(self) -> int:
        return 0

    def write(self, data: bytes) -> None:
        self.written += data
        self.answer = b"0\r"

    def read_until(self, _end: bytes) -> bytes:
        out, self.answer = self.answer, b""
        return out

    def read(self, _n: int) -> bytes:
        return b""


def entries(run: Callable[[], object], module: object) -> list[str]:
    """The calls into ``module`` from code outside it while ``run`` runs, by name."""
    room = str(Path(module.__file__))
    seen: list[str] = []

    def hook(frame, event, _arg) -> None:
        if event != "call" or frame.f_code.co_filename != room:
            return
        caller = frame.f_back
        if caller is None or caller.f_code.co_filename != room:
            seen.append(frame.f_code.co_name)

    sys.setprofile(hook)
    try:
        run()
    finally:
        sys.setprofile(None)
    return seen


def _link() -> Link:
    guard = Guard(load_profile("GVE84-100"), 0, max_travel=1000, allow_destructive=False)
    link = Link(_Port(), guard, virtual=False)
    link.send("V1000")                   # the first frame's own setup is not the walk
    return link


def test_a_frame_sent_visits_the_link_once_and_the_guard_before_and_after():
    link = _link()
    assert entries(lambda: link.send("V1000"), link_module) == ["send"]
    assert entries(lambda: link.send("V1000"), safety_module) == ["admit", "book"]


def test_raw_frames_and_their_answer_visit_the_guard_as_a_frame_does():
    link = _link()

    def exchange() -> None:
        link.send_raw(b"!0V1000\r")
        link.read_response()

    assert entries(exchange, safety_module) == ["admit", "book"]


def test_a_frame_due_no_answer_is_booked_once():
    link = _link()
    assert entries(lambda: link.send("*S", answer=False), safety_module) == ["admit", "book"]
    assert link.view.packet_open and link.guard.packet_open


def test_a_frame_told_ahead_is_judged_when_told_not_again_when_sent():
    link = _link()
    judged: list[str] = []
    check = link.guard.check
    link.guard.check = lambda body, address=None: (judged.append(body), check(body, address))
    link.port.ran = lambda data: True            # the co-simulator ran it when told
    assert link.send("V1000").ok and judged == []
    link.port.ran = lambda data: False
    assert link.send("V1000").ok and judged == ["V1000"]


def test_a_signal_still_stops_a_frame_told_ahead():
    link = _link()
    link.port.ran = lambda data: True
    link.guard.interrupts.signal()
    with pytest.raises(Interrupted):
        link.send("V1000")
    assert link.port.written.count(b"V1000") == 1      # the first, before the signal


def test_an_eeprom_write_told_ahead_is_in_the_ledger_once_sent():
    guard = Guard(load_profile("GVE84-100"), 0, max_travel=1000, allow_destructive=True)
    guard.eeprom.found({0x10: 0xFF})
    link = Link(_Port(), guard, virtual=False)
    link.port.ran = lambda data: True            # judged when told, on a copy of the guard
    link.send("EW10,55")
    assert guard.eeprom.written == {0x10}         # the session puts it back
