"""The receiving side in real time, on a clock of the test's own: after a frame timed
out, the next frame goes once the line has been silent for the late grace and an
answer's time since the answer was due (not a fixed quiet); an answer within the grace
is still its frame's, noted late; one after the grace, before the next frame, is the
timed-out frame's late answer (a FAIL of its own), never the next frame's. The end of a
case listens one slowest round trip, the silence since the line was last read counting,
and still catches a second answer."""

from __future__ import annotations

import pytest

from conformance.link import line_time as line_time_module
from conformance.link import receiver as receiver_module
from conformance.link.line_time import END_QUIET, LATE, MARGIN
from conformance.link.link import Link
from conformance.link.strays import LATE_RULE, TWICE
from conformance.targets import parse_target

CR = b"\r"


class _Clock:
    """Real time as the link reads it, moved only by the port's reads."""

    def __init__(self) -> None:
        self.t = 100.0

    def monotonic(self) -> float:
        return self.t

    def monotonic_ns(self) -> int:
        return round(self.t * 1e9)


class _Port:
    """A port on ``clock``: ``arrivals`` are (seconds after the port opened, bytes) the unit
    sends, ``replies`` what it sends 5 ms after a frame holding the key; a read waits for
    them up to its timeout, which then passes whole."""

    def __init__(self, clock: _Clock, arrivals: list[tuple[float, bytes]],
                 replies: dict[bytes, bytes] | None = None) -> None:
        self.clock, self.opened = clock, clock.t
        self.arrivals = sorted(arrivals)
        self.replies = replies or {}
        self.waiting, self.timeout, self.written = b"", 0.0, bytearray()

    def _arrive(self) -> None:
        while self.arrivals and self.opened + self.arrivals[0][0] <= self.clock.t:
            self.waiting += self.arrivals.pop(0)[1]

    def _wait(self, enough) -> None:
        """Let time pass until ``enough()`` or the timeout ran out."""
        deadline = self.clock.t + self.timeout
        self._arrive()
        while not enough():
            if not self.arrivals or self.opened + self.arrivals[0][0] > deadline:
                self.clock.t = deadline
                return
            self.clock.t = self.opened + self.arrivals[0][0]
            self._arrive()

    @property
    def in_waiting(self) -> int:
        self._arrive()
        return len(self.waiting)

    def write(self, data: bytes) -> None:
        self.written += data
        now = self.clock.t - self.opened
        self.arrivals = sorted(self.arrivals + [(now + 0.005, reply) for key, reply in
                                                self.replies.items() if key in data])

    def read_until(self, end: bytes) -> bytes:
        self._wait(lambda: end in self.waiting)
        cut = self.waiting.find(end) + 1 or len(self.waiting)
        got, self.waiting = self.waiting[:cut], self.waiting[cut:]
        return got

    def read(self, n: int) -> bytes:
        self._wait(lambda: bool(self.waiting))
        got, self.waiting = self.waiting[:n], self.waiting[n:]
        return got


@pytest.fixture
def clock(monkeypatch) -> _Clock:
    c = _Clock()
    monkeypatch.setattr(receiver_module, "time", c)
    monkeypatch.setattr(line_time_module, "time", c)
    return c


def _link(port: _Port) -> Link:
    guard = parse_target("emu:GVE84-100").session.open_link().guard
    return Link(port, guard, virtual=False, baud=38400)


def test_the_quiet_is_the_late_grace_and_an_answers_time():
    ln = _link(_Port(_Clock(), []))
    assert ln.time.quiet() == pytest.approx(LATE + MARGIN + 64 * 10 / 38400)
    ln.round_trip = {"max_ms": 12.0}           # a USB adapter's line: its delay too
    assert ln.time.quiet() == pytest.approx(LATE + MARGIN + 64 * 10 / 38400 + 0.024)


def test_the_next_frame_goes_once_the_line_was_silent_that_long_since_the_answer_was_due(
        clock):
    port = _Port(clock, [])
    ln = _link(port)
    sent = clock.t
    timeout = ln.answer_timeout("V1000", 8)
    assert ln.send("V1000") is None             # not even within the late grace
    assert clock.t - sent == pytest.approx(timeout + LATE)
    ln.settle()                                  # the quiet before the next frame
    # the grace heard silent counts: what is left is an answer's time, not the quiet anew
    assert clock.t - sent == pytest.approx(timeout + ln.time.quiet(), abs=0.06)
    before = clock.t
    ln.settle()                                  # kept once
    assert clock.t == before


def test_an_answer_within_the_grace_is_its_frames_noted_late(clock):
    timeout = _link(_Port(_Clock(), [])).answer_timeout("SR6", 6)
    port = _Port(clock, [(timeout + 0.9, b"0,12\r")])
    ln = _link(port)
    r = ln.send("SR6")
    assert r is not None and r.raw == b"0,12\r"
    assert ln.violations == [] and len(ln.late) == 1


def test_an_answer_after_the_grace_is_the_timed_out_frames_late_answer_not_the_next_ones(
        clock):
    timeout = _link(_Port(_Clock(), [])).answer_timeout("V1000", 8)
    # V1000 answered after its grace, before the quiet ended; SR6 answered at once
    port = _Port(clock, [(timeout + LATE + 0.1, b"0\r")], {b"SR6": b"0,00\r"})
    ln = _link(port)
    assert ln.send("V1000") is None
    r = ln.send("SR6")
    assert r is not None and r.raw == b"0,00\r"
    assert [v.rule for v in ln.violations] == [LATE_RULE]


def test_the_end_of_a_case_listens_one_slowest_round_trip():
    ln = _link(_Port(_Clock(), []))
    ln.round_trip = {"max_ms": 12.0}
    assert ln.time.end_quiet() == pytest.approx(0.012)
    ln.round_trip = {"max_ms": 80.0}            # never more than END_QUIET
    assert ln.time.end_quiet() == pytest.approx(END_QUIET)


def test_the_end_of_a_case_counts_the_silence_since_the_line_was_last_read(clock):
    port = _Port(clock, [], {b"SR6": b"0,00\r"})
    ln = _link(port)
    ln.round_trip = {"max_ms": 12.0}
    assert ln.send("SR6").raw == b"0,00\r"
    clock.t += 0.02                              # the case's own work after its last read
    before = clock.t
    ln.settle(final=True)
    assert clock.t == before and ln.violations == []


@pytest.mark.parametrize(("work", "after"), [(0.02, 0.004), (0.005, 0.01)])
def test_a_second_answer_is_still_caught_at_the_end_of_a_case(clock, work, after):
    """Right behind the first: while the case worked after its last read (waiting in
    the port), or after that, within the round trip."""
    port = _Port(clock, [], {b"SR6": b"0,00\r"})
    ln = _link(port)
    ln.round_trip = {"max_ms": 12.0}
    assert ln.send("SR6").raw == b"0,00\r"
    port.arrivals.append((clock.t - port.opened + after, b"0,00\r"))
    clock.t += work
    ln.settle(final=True)
    assert [v.rule for v in ln.violations] == [TWICE]
