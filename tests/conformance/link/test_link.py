"""How long the link waits for an answer and whether it reads one summed: one rule for
its own frames and for the raw frames the differential sides send."""

import pytest

from conformance.diff.sides import Side
from conformance.link import line_time as line_time_module
from conformance.link.line_time import LATE
from conformance.link.link import Link
from conformance.targets import parse_target
from gve_fixtures.protocol import SECOND


def link():
    return parse_target("emu:GVE84-100").session.open_link()


def test_an_answer_given_when_the_action_ends_may_take_that_long():
    ln = link()
    immediate = ln.answer_timeout("V1000", 8)
    assert immediate < 1                         # the bytes and a margin
    assert ln.answer_timeout("V1000", 80) > immediate
    slow = ln.guard.answer_seconds("H")
    assert slow > 0 and ln.answer_timeout("H", 8) - immediate == pytest.approx(slow)


def test_the_answer_is_summed_as_the_mode_is_after_the_command():
    ln = link()
    assert ln.summed_after("%+") and not ln.summed_after("V1000")
    ln.checksums = True
    assert ln.summed_after("V1000") and not ln.summed_after("%-") and not ln.summed_after("J")


def test_a_side_reads_the_answer_to_a_mode_change_as_the_link_does():
    side = Side(parse_target("emu:GVE84-100"))
    side.open()
    on = side.exchange(b"!0%+\r", body="%+")
    assert on.code == 0 and on.response.checksum is not None
    assert side.link.send("%-").code == 0


class _Line:
    """A real-time port whose answers come as scripted: each ``read_until`` returns the
    next piece (``b""``: its timeout ran out); ``then`` arrives after the last piece."""

    def __init__(self, pieces: list[bytes], then: bytes = b"") -> None:
        self.pieces, self.then, self.waiting, self.timeout = list(pieces), then, b"", None
        self.timeouts: list[float] = []
        self.written = bytearray()

    @property
    def in_waiting(self) -> int:
        return len(self.waiting)

    def write(self, data: bytes) -> None:
        self.written += data

    def read_until(self, _end: bytes) -> bytes:
        self.timeouts.append(self.timeout)
        piece = self.pieces.pop(0) if self.pieces else b""
        if not self.pieces:
            self.waiting, self.then = self.waiting + self.then, b""
        return piece

    def read(self, n: int) -> bytes:
        got, self.waiting = self.waiting[:n], self.waiting[n:]
        return got


def real_link(port: _Line) -> Link:
    return Link(port, link().guard, virtual=False)


def test_an_answer_after_its_timeout_is_its_frames_answer_noted_late():
    port = _Line([b"", b"0,12\r"])            # nothing in time, then the whole answer
    ln = real_link(port)
    r = ln.send("SR6")
    assert r is not None and r.raw == b"0,12\r"
    assert ln.violations == [] and len(ln.late) == 1 and "SR6" in ln.late[0]
    assert port.timeouts[1:] == [LATE]


def test_a_late_answer_then_another_is_still_answered_twice():
    port = _Line([b"", b"0\r"], then=b"0\r")
    ln = real_link(port)
    assert ln.send("V1000").raw == b"0\r"
    assert len(ln.late) == 1 and any("answered twice" in v.text for v in ln.violations)


def test_a_timeout_the_caller_chose_takes_no_late_answer():
    port = _Line([b"", b"0\r"])
    ln = real_link(port)
    assert ln.send("V1000", timeout=0.1) is None and ln.late == []
    assert port.timeouts == [0.1]


def test_a_frame_after_a_timed_out_one_counts_its_round_trip_from_the_quiet_lines_end(
        monkeypatch):
    # the quiet kept before it is the link's, not the line's: a round trip counted from
    # before it would widen every band read from the round trips by that much
    monkeypatch.setattr(line_time_module, "LATE", 0.0)
    port = _Line([b"", b"0,12\r"])           # V1000 unanswered, SR6 answered at once
    ln = real_link(port)
    assert ln.send("V1000") is None
    r = ln.send("SR6")
    assert r is not None and r.raw == b"0,12\r"
    assert r.received_at - r.sent_at < 0.5 * SECOND
    assert r.sent_at == ln.wrote_at


def test_the_quiet_after_a_timed_out_frame_is_kept_once(monkeypatch):
    monkeypatch.setattr(line_time_module, "LATE", 0.0)
    port = _Line([b""])
    ln = real_link(port)
    # (the quiet counts from the instant the answer was due, inside send: no later than
    # send's return, no earlier than its call)
    sent = ln.now
    assert ln.send("V1000") is None
    ln.settle()                                # waits for the quiet line
    kept = ln.now
    ln.settle()                                # the line is known quiet: no second wait
    assert kept - sent >= ln.time.quiet() * SECOND > ln.now - kept


def test_a_rate_the_case_sets_is_the_one_the_link_waits_by():
    """A case that moves the line to another rate tells the link (its time is the
    bytes' at that rate)."""
    ln = link()
    fast = ln.answer_timeout("V1000", 8)
    ln.baud = 9600
    assert ln.baud == 9600 and ln.byte_seconds(1) == pytest.approx(10 / 9600)
    assert ln.answer_timeout("V1000", 8) > fast
