"""The reference's course through an example: the dwell a frame may meet, the fastest
rate its axes can have stepped at, the junction of two C and the open packet."""

from hypothesis import given, settings
from hypothesis import strategies as st

from conformance.diff.course import Course
from conformance.diff.sides import RoundTrip
from conformance.diff.steps import FRAME, Step
from conformance.link.framing import parse_response
from conformance.protocol.view import View, observe
from conformance.targets import parse_target
from tests.conformance.protocol.test_view import ANSWERS, FRAMES

MS = 1_000_000


def course() -> Course:
    return Course(parse_target("emu:GVE84-100").profile)     # T5, V1000, XM100


def ok(at_ms: int = 0, code: int = 0) -> RoundTrip:
    """The reference's answer ``code``, the frame sent ``at_ms`` into the example."""
    answer = f"{code}\r".encode()
    return RoundTrip(b"", answer, at_ms * MS, at_ms * MS, parse_response(answer, summed=False))


def test_a_frame_within_t_of_a_vector_may_meet_its_dwell():
    c = course()
    c.took("C", "C5,0,0", ok(10))
    assert c.within_dwell(14 * MS) and not c.within_dwell(15 * MS)
    c.took("T", "T20", ok(11))
    assert c.within_dwell(29 * MS)
    c.took("H", "H", ok(12))                    # what follows is the halt's
    assert not c.within_dwell(13 * MS)


def test_a_vector_that_moves_nothing_or_is_refused_sets_no_dwell():
    c = course()
    c.took("L", "L0,-0,+0", ok(10))
    c.took("C", "C5,0,0", ok(10, code=1))
    c.took("C", "C5,0,0", ok(10), first=False)   # a fill's later frame joins the first
    assert not c.within_dwell(11 * MS)


def test_the_rate_ceiling_follows_v_xm_xu_and_the_top_rate():
    c = course()
    assert c.rate == 1000
    c.took("V", "V2000", ok())
    c.took("V", "V500", ok())                   # the highest V taken stands
    c.took("XM", "XM150", ok())
    assert c.rate == 3000
    c.took("XU", "XU", ok())
    assert c.rate == 3188                       # 3000 * 17/16, rounded up
    c.took("W", "W", ok())
    assert c.rate == 100000


def test_two_c_meet_at_a_junction_until_d():
    c = course()
    c.took("C", "C1,0,0", ok())
    assert not c.junction
    c.took("C", "C0,1,0", ok())
    assert c.junction
    c.took("D", "D", ok())
    c.took("C", "C1,0,0", ok())
    assert not c.junction


def silent(at_ms: int = 0) -> RoundTrip:
    """The reference answered nothing."""
    return RoundTrip(b"", b"", at_ms * MS, at_ms * MS, None)


def test_a_packet_opens_on_the_units_own_star_s_and_closes_on_a_breaker():
    c = course()
    c.exchanged(Step(FRAME, "*S", address=3), silent())
    assert not c.in_packet
    c.exchanged(Step(FRAME, "*S"), silent())
    c.exchanged(Step(FRAME, "C1,0,0"), silent())
    assert c.in_packet and c.wire.packet == ("C1,0,0",)
    c.exchanged(Step(FRAME, "@"), ok())
    assert not c.in_packet


def test_the_open_packet_is_the_one_view_s_of_the_reference_s_answers():
    """Decided (docs/decisions.md, "one view of the unit"): an `*S` the reference
    answered opened nothing, and a frame it answered inside a packet ended it."""
    c = course()
    c.exchanged(Step(FRAME, "*S"), ok(code=4))
    assert not c.in_packet
    c.exchanged(Step(FRAME, "*S"), silent())
    c.exchanged(Step(FRAME, "V100"), ok())
    assert not c.in_packet
    c.exchanged(Step(FRAME, "*S"), silent())
    c.powered_on()
    assert not c.in_packet


def test_a_position_beyond_every_vector_taken_is_beyond_reach():
    c = Course(parse_target("emu:GVE54").profile)              # MF: 1 sixteenth a step
    c.took("M", "M8", ok())                                    # 2 sixteenths a step
    c.took("L", "L20,0,0", ok())
    c.took("L", "L0,-5,0", ok(1, code=5))                      # refused: goes nowhere
    assert c.beyond_reach(["41", "0", "0"]) and not c.beyond_reach(["40", "0", "0"])
    assert c.beyond_reach(["0", "-1", "0"])
    c.took("NX", "NX100", ok())                                # a counter set: unknown
    assert not c.beyond_reach(["1000", "0", "0"])


def test_vl_capping_only_axes_never_moved_below_the_rate_is_capped_elsewhere():
    c = course()                                               # V1000
    c.took("VL", "VL100,1000,1000", ok())
    assert not c.capped_elsewhere                              # nothing moved yet
    c.took("L", "L0,300,0", ok())
    assert c.capped_elsewhere
    c.took("L", "L10,0,0", ok(1))                              # X moves: its cap acts
    assert not c.capped_elsewhere
    c = course()
    c.took("VL", "VL1000,1000,1000", ok())
    c.took("L", "L0,300,0", ok())
    assert not c.capped_elsewhere                              # no cap below the rate


@settings(max_examples=150, deadline=None)
@given(st.lists(st.tuples(st.sampled_from(FRAMES), st.sampled_from(ANSWERS),
                          st.sampled_from([None, 3, 7])), max_size=20))
def test_the_course_keeps_no_packet_of_its_own(exchanges):
    """Whatever the reference answered, the course's open packet is that of the one view
    fed the frames to the unit and its spindle's address (protocol/view.py)."""
    c = Course(parse_target("emu:GVE114-500").profile)          # the spindle at 7
    wire = View(addresses=frozenset({0, 7}))
    for body, raw, address in exchanges:
        answer = None if raw is None else parse_response(raw, summed=False)
        c.exchanged(Step(FRAME, body, address=address), RoundTrip(b"", raw or b"", 0, 0,
                                                                  answer))
        wire = observe(wire, body, answer, address)
    assert c.in_packet == wire.packet_open


def test_the_hand_wheel_sent_on_without_eeprom_06_enabling_it_is_a_reading():
    c = Course(parse_target("emu:GVE114-500").profile)       # EEPROM 06 as shipped: FF
    assert "mpg-disabled" not in c.context(0, "SR", "SR6", None)   # reset's & alone
    c.took("Y", "Y+", ok(1))
    assert "mpg-disabled" in c.context(2 * MS, "SR", "SR6", None)
    c.took("Y", "Y-", ok(3))
    assert "mpg-disabled" not in c.context(4 * MS, "SR", "SR6", None)
    c.took("Y", "Y&", ok(5))
    c.took("EW", "EW06,01", ok(6))                           # enabling: the manual's case
    assert "mpg-disabled" not in c.context(7 * MS, "SR", "SR6", None)
