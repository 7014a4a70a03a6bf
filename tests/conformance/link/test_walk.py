"""A frame's walk from its sender to the target and back visits the link once and the
guard once per exchange, before the write (Guard.admit); after the read the link tells
the exchange once to each of those who follow the unit (its bookkeeping, its liveness),
never to the guard: traced with a profiler hook (sys.setprofile) that notes every call
into each module from another module (the link's two, link.py and its receiving side
receiver.py, as one)."""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path

import pytest

from conformance.link import bookkeeping as bookkeeping_module
from conformance.link import link as link_module
from conformance.link import liveness as liveness_module
from conformance.link import receiver as receiver_module
from conformance.link import safety as safety_module
from conformance.link.link import Link
from conformance.link.safety import Guard
from conformance.link.signals import Interrupted
from conformance.targets import parse_target
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


def entries(run: Callable[[], object], *modules: object) -> list[str]:
    """The calls into ``modules`` (one room) from code outside them while ``run`` runs,
    by name."""
    room = {str(Path(module.__file__)) for module in modules}
    seen: list[str] = []

    def hook(frame, event, _arg) -> None:
        if event != "call" or frame.f_code.co_filename not in room:
            return
        caller = frame.f_back
        if caller is None or caller.f_code.co_filename not in room:
            seen.append(frame.f_code.co_name)

    sys.setprofile(hook)
    try:
        run()
    finally:
        sys.setprofile(None)
    return seen


#: the link's modules: the link and its receiving side
LINK = (link_module, receiver_module)


def _link() -> Link:
    guard = Guard(load_profile("GVE84-100"), 0, max_travel=1000, allow_destructive=False)
    link = Link(_Port(), guard, virtual=False)
    link.send("V1000")                   # the first frame's own setup is not the walk
    return link


def visits(run: Callable[[], object]) -> dict[str, list[str]]:
    """The calls the link makes into the guard and into those who follow the unit while
    ``run`` runs, by module (what the guard itself reads of them is its own)."""
    link = {str(Path(m.__file__)) for m in LINK}
    rooms = {str(Path(m.__file__)): name for name, m in
             (("guard", safety_module), ("bookkeeping", bookkeeping_module),
              ("liveness", liveness_module))}
    seen: dict[str, list[str]] = {name: [] for name in rooms.values()}

    def hook(frame, event, _arg) -> None:
        room = rooms.get(frame.f_code.co_filename)
        if event == "call" and room and frame.f_back is not None \
                and frame.f_back.f_code.co_filename in link:
            seen[room].append(frame.f_code.co_name)

    sys.setprofile(hook)
    try:
        run()
    finally:
        sys.setprofile(None)
    return seen


#: one exchange's walk: the guard asked once, before the write; the exchange told once
#: to those who follow the unit after the read
ONCE = {"guard": ["admit"], "bookkeeping": [], "liveness": ["tell_followers"]}


def test_a_frame_sent_visits_the_link_once_and_the_guard_once():
    link = _link()
    assert entries(lambda: link.send("V1000"), *LINK) == ["send"]
    assert entries(lambda: link.send("V1000"), safety_module) == ["admit"]
    assert visits(lambda: link.send("V1000")) == ONCE


def test_raw_frames_and_their_answer_visit_the_guard_as_a_frame_does():
    link = _link()

    def exchange() -> None:
        link.send_raw(b"!0V1000\r")
        link.read_response()

    assert entries(exchange, safety_module) == ["admit"]
    assert visits(exchange) == ONCE


def test_a_frame_due_no_answer_is_booked_once():
    link = _link()
    assert visits(lambda: link.send("*S", answer=False)) == ONCE
    assert link.view.packet_open and link.guard.packet_open


def test_on_the_emulator_each_exchange_visits_the_guard_once():
    """Against the in-process emulator, the guard's public methods called during a few
    exchanges, counted by wrapping them: `admit` once per exchange and nothing else; the
    link tells each exchange once to the bookkeeping and once to the liveness."""
    link = parse_target("emu:GVE84-100").open_link()
    link.send("SR6")                     # the first frame's own setup is not the walk
    guard = link.guard
    calls: list[str] = []
    inside: list[str] = []               # a guard's call to its own methods is not a visit

    def counted(method: Callable, name: str) -> Callable:
        def call(*args, **kwargs):
            if not inside:
                calls.append(name)
            inside.append(name)
            try:
                return method(*args, **kwargs)
            finally:
                inside.pop()
        return call

    public = [n for n in dir(Guard) if not n.startswith("_")
              and callable(getattr(Guard, n)) and not isinstance(getattr(Guard, n), property)]
    for name in public:
        setattr(guard, name, counted(getattr(guard, name), name))
    bookkeeping, liveness = link._followers
    bookkeeping.book = counted(bookkeeping.book, "book")
    liveness.heard = counted(liveness.heard, "heard")
    bodies = ["V1000", "SR6", "*S", "C1,0,0", "*E1", "PF"]
    for body in bodies:
        calls.append(body)
        link.send(body, answer=body not in ("*S", "C1,0,0"))
    assert calls == [x for body in bodies for x in (body, "admit", "book", "heard")]


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
