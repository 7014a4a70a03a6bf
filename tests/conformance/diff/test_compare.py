"""Two answers compared: exact in virtual time, positions within the band in real time
while the axes may move, exact at rest; the index from where each side began."""

from conformance.diff.compare import Judge, alike_because, delays, difference
from conformance.diff.sides import RoundTrip
from conformance.link.framing import parse_response
from conformance.link.line_band import LineBand

MS = 1_000_000


def ex(answer: bytes, sent_at: int = 0, received_at: int = MS) -> RoundTrip:
    r = parse_response(answer, summed=False) if answer else None
    return RoundTrip(b"!0PF\r", answer, sent_at, received_at, r)


def test_alike_answers_at_the_same_instant_agree():
    assert difference("PF", ex(b"0,1,2,3\r"), ex(b"0,1,2,3\r"), Judge()) is None


def test_in_virtual_time_an_answer_at_another_instant_is_a_timing_difference():
    assert difference("H", ex(b"8\r", 0, MS), ex(b"8\r", 0, 5 * MS), Judge()) == "timing"


def test_two_silences_are_alike_however_long_each_side_was_listened_to():
    # where each stopped listening is the suite's, not the unit's
    assert difference("W", ex(b"", 0, MS), ex(b"", 0, 400 * MS), Judge()) is None


def test_a_timing_difference_shows_two_different_instants():
    assert delays(ex(b"8\r", 0, MS), ex(b"8\r", 0, 5 * MS)) == ("1.000 ms", "5.000 ms")
    # as many decimals as tell them apart, to the nanosecond
    assert delays(ex(b"8\r", 0, MS), ex(b"8\r", 0, MS + 1)) == ("1.000000 ms", "1.000001 ms")
    assert delays(ex(b"8\r", 2, MS + 2), ex(b"8\r", 0, MS)) == ("1.000 ms", "1.000 ms")


def test_kinds():
    judge = Judge()
    assert difference("V", ex(b"0\r"), ex(b""), judge) == "silence"
    assert difference("V", ex(b"4\r"), ex(b"5\r"), judge) == "code"
    assert difference("V", ex(b"0\r"), ex(b"8\r"), judge) == "inta"
    assert difference("PF", ex(b"0,1,2,3\r"), ex(b"0,1,2,4\r"), judge) == "position"
    assert difference("SR", ex(b"0,01\r"), ex(b"0,FF\r"), judge) == "data"


def test_real_time_positions_within_the_band_while_moving_and_exact_at_rest():
    judge = Judge(exact=False, rate=1000)                  # 1000 steps/s: 1 step per ms
    near, far = ex(b"0,100,0,0\r", 0, 2 * MS), ex(b"0,103,0,0\r", 0, 0)
    assert difference("PF", near, far, judge, moving=True) is None     # 2 ms + placement
    assert difference("PF", ex(b"0,110,0,0\r", 0, 2 * MS), far, judge, moving=True) \
        == "position"
    assert difference("PF", near, far, judge, moving=False) == "position"


def test_real_time_at_rest_after_a_course_change_within_its_latency():
    """An H (or G, XM, an input...) sent while the axes ran: the target acted on it up to
    its latency later than the reference did, so even at rest the positions may differ by
    the rate times that latency, plus placement; no further."""
    judge = Judge(exact=False, rate=1000, slack_ns=6 * MS)              # 6 steps late
    at_rest = ex(b"8,300,0,0\r", 0, 0)
    assert difference("PF", ex(b"8,306,0,0\r"), at_rest, judge) is None
    assert difference("PF", ex(b"8,307,0,0\r"), at_rest, judge) is None    # placement
    assert difference("PF", ex(b"8,308,0,0\r"), at_rest, judge) == "position"
    assert difference("PF", ex(b"8,301,0,0\r"), at_rest, Judge(exact=False, rate=1000)) \
        == "position"


def test_real_time_the_line_band_widens_the_target_s_window_and_its_lateness():
    """Behind a line with a 4 ms band the target may have read its counters 4 ms either
    side of its exchange, and acted on a course change 4 ms later still."""
    judge = Judge(exact=False, rate=1000, line=LineBand(4e-3))
    far = ex(b"0,103,0,0\r", 0, 0)
    # 2 ms window + 4 ms either side: 6 ms from the reference's instant, + placement
    assert difference("PF", ex(b"0,96,0,0\r", 0, 2 * MS), far, judge, moving=True) is None
    assert difference("PF", ex(b"0,95,0,0\r", 0, 2 * MS), far, judge, moving=True) \
        == "position"
    at_rest = ex(b"8,300,0,0\r", 0, 0)
    late = Judge(exact=False, rate=1000, slack_ns=6 * MS, line=LineBand(4e-3))  # 10 steps
    assert difference("PF", ex(b"8,311,0,0\r"), at_rest, late) is None      # placement
    assert difference("PF", ex(b"8,312,0,0\r"), at_rest, late) == "position"
    # at rest with nothing that changed the course: still exact, whatever the line
    assert difference("PF", ex(b"8,301,0,0\r"), at_rest, judge) == "position"
    assert alike_because("PF", ex(b"0,96,0,0\r", 0, 2 * MS), far, judge, moving=True) == \
        "within ±7 step(s) (±4.0 ms line), read while the axes may have moved"


def test_real_time_index_compared_from_where_each_side_began():
    judge = Judge(exact=False, index_offset=40)
    assert difference("@", ex(b"0,45\r"), ex(b"0,5\r"), judge) is None
    assert difference("@", ex(b"0,46\r"), ex(b"0,5\r"), judge) == "data"


def repeat(answer: bytes, received_at: int = 2 * MS) -> RoundTrip:
    return RoundTrip(b"!0>\r", answer, 0, received_at, parse_response(answer, summed=False,
                                                                      lines=2), 2)


def test_real_time_a_repeated_position_read_is_compared_as_that_read():
    judge = Judge(exact=False, rate=1000)
    near, far = repeat(b"!0PF\r0,-1,36,275\r"), repeat(b"!0PF\r0,-1,35,273\r", 0)
    assert difference(">", near, far, judge, moving=True) is None
    assert difference(">", repeat(b"!0PF\r0,-1,36,299\r"), far, judge, moving=True) \
        == "position"
    # another repeated command's values stay exact; in virtual time everything does
    assert difference(">", repeat(b"!0SR0\r0,01\r"), repeat(b"!0SR0\r0,02\r", 0), judge,
                      moving=True) == "data"
    assert difference(">", near, repeat(b"!0PF\r0,-1,35,273\r"), Judge(), moving=True) \
        == "position"


def test_in_virtual_time_somebody_else_s_unit_may_place_its_steps_its_own_way():
    # a target not graded by our decisions: a step either side on each axis, and H at
    # rest two step periods either side (placed a period later, it stops a period later,
    # and the stop's last step lands where its own steps put it); nothing more
    judge = Judge(placement=1, period_ns=10 * MS)
    assert difference("PF", ex(b"0,305,-102,0\r"), ex(b"0,306,-101,0\r"), judge) is None
    assert difference("PF", ex(b"0,304,-102,0\r"), ex(b"0,306,-102,0\r"), judge) == "position"
    assert difference("H", ex(b"8\r", 0, 21 * MS), ex(b"8\r", 0, 1 * MS), judge) is None
    assert difference("H", ex(b"8\r", 0, 22 * MS), ex(b"8\r", 0, 1 * MS), judge) == "timing"
    assert difference("V", ex(b"0\r", 0, 2 * MS), ex(b"0\r", 0, MS), judge) == "timing"
    assert "±1 step" in alike_because("PF", ex(b"0,305,0,0\r"), ex(b"0,306,0,0\r"), judge)


def test_in_virtual_time_the_reference_s_own_kind_is_exact():
    judge = Judge()
    assert difference("PF", ex(b"0,305,0,0\r"), ex(b"0,306,0,0\r"), judge) == "position"
    assert difference("H", ex(b"8\r", 0, 2 * MS), ex(b"8\r", 0, 1 * MS), judge) == "timing"


def test_an_input_port_is_compared_in_the_bits_with_pins_only():
    judge = Judge(unused_inputs=((2, 0x3F),))
    # the GVE114's I2 bits 0-5 are unused: read 1 or 0 there, the same pins
    assert difference("I2", ex(b"0,3F\r"), ex(b"0,00\r"), judge) is None
    assert "unused" in alike_because("I2", ex(b"0,3F\r"), ex(b"0,00\r"), judge)
    assert difference("I2", ex(b"0,BF\r"), ex(b"0,00\r"), judge) == "data"   # bit 7 differs
    assert difference("I1", ex(b"0,3F\r"), ex(b"0,00\r"), judge) == "data"   # every pin used
    assert difference("I2", ex(b"0,3F\r"), ex(b"0,00\r"), Judge()) == "data"
