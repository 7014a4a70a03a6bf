"""Where a pair's sides begin: whether a power-on left the checksum mode on is asked of
the target only where no frame came after the power-on, as a session asks a unit it
finds (`?` without its sum refused 4, with it taken)."""

from __future__ import annotations

from conformance.diff.start import left_summing
from conformance.diff.steps import FRAME, RIG, WAIT, Step
from conformance.protocol.wire import Response, parse_response


class Line:
    """A target's link that answers `?` as a unit left summing does."""

    def __init__(self, summing: bool = True) -> None:
        self.summing = summing
        self.asked: list[tuple[str, bool]] = []

    def send(self, body: str, *, checksum: bool) -> Response:
        self.asked.append((body, checksum))
        refused = self.summing and not checksum
        return parse_response(b"4\r" if refused else b"0\r", summed=False)


def test_a_power_on_with_no_frame_after_it_is_asked_about():
    line = Line()
    assert left_summing([Step(RIG, "power-on"), Step(WAIT, seconds=0.1)], False, line)
    assert line.asked == [("?", False), ("?", True)]
    assert left_summing([], True, Line())                  # the sequence began at one


def test_nothing_is_asked_after_a_frame_or_with_no_power_on():
    line = Line()
    assert not left_summing([Step(RIG, "power-on"), Step(FRAME, "V10")], False, line)
    assert not left_summing([Step(WAIT, seconds=0.1)], False, line)
    assert line.asked == []


def test_a_unit_that_takes_a_plain_frame_was_not_left_summing():
    line = Line(summing=False)
    assert not left_summing([Step(RIG, "power-on")], False, line)
    assert line.asked == [("?", False)]
