"""The line's band from its measured round trip: half the median less the exchange's
bytes, the jitter, one byte; widened by a case's own round trips; zero when exact."""

from __future__ import annotations

import pytest

from conformance.link.line_band import EXACT, LineBand, acted_within, line_band

LINE = {"min_ms": 1.0, "median_ms": 3.0, "max_ms": 4.0, "byte_ms": 0.5, "bytes_ms": 1.0}


def test_one_way_latency_plus_jitter_plus_a_byte() -> None:
    # (3 - 1) / 2 = 1 ms one way, 4 - 1 = 3 ms jitter, 0.5 ms a byte
    assert line_band(LINE).seconds == pytest.approx(4.5e-3)
    assert str(line_band(LINE)) == "±4.5 ms line"


def test_the_jitter_is_the_case_s_own_when_it_saw_two_round_trips_or_more() -> None:
    # 0.5..6: jitter 5.5 ms; the median stays the session's
    assert line_band(LINE, [0.5, 6.0]).seconds == pytest.approx(7.0e-3)
    # 2.0..2.5: a quiet line during the case, whatever the session's slowest `?` was
    assert line_band(LINE, [2.0, 2.5]).seconds == pytest.approx(2.0e-3)
    # one round trip alone: the session's 1..4, widened by it
    assert line_band(LINE, [2.0]).seconds == pytest.approx(4.5e-3)
    assert line_band(LINE, [9.0]).seconds == pytest.approx(9.5e-3)


def test_bytes_that_take_no_time_leave_no_negative_latency() -> None:
    # a pty: the bytes' time at the baud rate exceeds the round trip itself
    pty = {"min_ms": 0.4, "median_ms": 0.5, "max_ms": 1.2, "byte_ms": 0.1, "bytes_ms": 2.0}
    assert line_band(pty).seconds == pytest.approx(0.9e-3)


def test_a_case_alone_measures_its_line_when_the_session_did_not() -> None:
    # median 2 of [1, 2, 5]: one way 1 ms, jitter 4 ms
    assert line_band({}, [5.0, 1.0, 2.0]).seconds == pytest.approx(5.0e-3)


def test_nothing_measured_is_exact() -> None:
    assert line_band(None) == line_band({}) == EXACT and EXACT.exact


def test_steps_and_widened_instants() -> None:
    band = LineBand(4.5e-3)
    assert band.steps(1000) == 5 and band.steps(0) == 0
    assert band.ns == 4_500_000
    assert band.widen(10_000_000, 12_000_000) == (5_500_000, 16_500_000)


def test_a_frame_answered_at_its_end_was_acted_on_as_late_as_its_answer_shows() -> None:
    ms = 1_000_000
    # sent at 10 ms, answered at 75 ms, what it does takes 50: taken up to 15 ms late,
    # though no immediate answer took more than 2
    assert acted_within(10 * ms, 75 * ms, 50 * ms, 2 * ms) == 15 * ms
    # an answer as soon as the frame's work allows: the latency of the frames before
    assert acted_within(10 * ms, 61 * ms, 50 * ms, 2 * ms) == 2 * ms
    # an answer sooner than its work takes (a unit that stops dead) widens nothing
    assert acted_within(10 * ms, 11 * ms, 50 * ms, 0) == 0
