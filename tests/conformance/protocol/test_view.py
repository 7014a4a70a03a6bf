"""The one view of a unit from the wire: where the suite's earlier trackers of the open
packet and the checksum mode agreed, the view agrees; where they disagreed, it follows a
named decision (docs/decisions.md, "one view of the unit"), each tested here."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from conformance.protocol.catalogue import classes
from conformance.protocol.index import Form
from conformance.protocol.parse import parse
from conformance.protocol.view import View, answered_late, late, observe
from conformance.protocol.wire import Response, parse_response

_BREAKERS = classes(packet="breaker")
_MEMBERS = classes(packet="member")
FRAMES = ["*S", "*E0", "*E2", "C1,0,0", "B500", "V100", "H", "@", "J", "%+", "%-",
          "L1,0,0", "SR6", "P"]
ANSWERS = [None, b"0\r", b"4\r", b"8\r", b"0,2\r", b"4,0\r", b"0,1,2,3\r", b"0,00\r"]


def answer(raw: bytes | None) -> Response | None:
    return None if raw is None else parse_response(raw, summed=False)


# -- the earlier trackers' rules, as they read the wire (the oracles of the property) --------
def link_packet(is_open: bool, name: str, r: Response | None) -> bool:
    """The link's: an answered `*S` opens nothing; an answered `*E` or breaker closes."""
    if name == "*S":
        return r is None
    if r is not None and r.code is not None and (name == "*E" or name in _BREAKERS):
        return False
    return is_open


def guard_packet(is_open: bool, name: str, r: Response | None) -> bool:
    """The guard's: any `*S` opens, any `*E` closes, a breaker answered closes; members
    change nothing."""
    if name in _MEMBERS and is_open:
        return True
    if name == "*S":
        return True
    if name == "*E":
        return False
    if name in _BREAKERS and r is not None:
        return False
    return is_open


def host_packet(is_open: bool, name: str, r: Response | None) -> bool:
    """Host certification's unit view: unanswered, `*S` opens and anything else is a
    member; answered, a breaker or `*E` closes."""
    if r is None or r.code is None:
        return True if name == "*S" else is_open
    if name in _BREAKERS or name == "*E":
        return False
    return is_open


def course_packet(is_open: bool, name: str, r: Response | None) -> bool:
    """diff's course, and the machines' model (as its machines booked what they sent):
    `*S` opens, `*E` and the breakers close, as they are sent."""
    if name == "*S":
        return True
    if name == "*E" or name in _BREAKERS:
        return False
    return is_open


PACKET_TRACKERS = (link_packet, guard_packet, host_packet, course_packet)


def link_mode(on: bool, body: str, r: Response | None) -> bool:
    """The link's (and host certification's, and the model's: a machine set it once the
    unit took `%+` or `%-`): `%+`, `%-` and `J` taken set the mode."""
    if r is None or not r.ok:
        return on
    return {"%+": True, "%-": False, "J": False}.get(body, on)


@settings(max_examples=300, deadline=None)
@given(st.lists(st.tuples(st.sampled_from(FRAMES), st.sampled_from(ANSWERS)), max_size=30))
def test_the_view_agrees_with_the_earlier_trackers_where_they_agreed(exchanges):
    view = View()
    packets = [False] * len(PACKET_TRACKERS)
    mode = False
    for body, raw in exchanges:
        r = answer(raw)
        name = parse(body).key
        before = view.packet_open
        view = observe(view, body, r)
        mode = link_mode(mode, body, r)
        assert view.checksums == mode
        packets = [t(p, name, r) for t, p in zip(PACKET_TRACKERS, packets, strict=True)]
        answered = r is not None and r.code is not None
        if before and answered and name != "*E" and name not in _BREAKERS:
            # decided: a frame answered inside a packet ends it (they all kept it open)
            assert not view.packet_open
        elif len(set(packets)) == 1:
            assert view.packet_open == packets[0], (body, raw, packets)
        # where they disagreed the view's decision stands; each is tested below, and
        # the trackers go on from the view's state
        packets = [view.packet_open] * len(PACKET_TRACKERS)


def test_decided_an_answered_star_s_opens_no_packet():
    view = observe(View(), "*S", answer(b"4\r"))
    assert not view.packet_open
    assert observe(View(), "*S", None).packet_open


def test_decided_an_unanswered_star_e_leaves_the_packet_open_yet_is_owed_its_answer():
    view = observe(observe(View(), "*S", None), "*E1", None)
    assert view.packet_open and view.packet == ("*E1",)
    assert not view.silent_by_rule                   # its silence counts as one
    assert observe(observe(View(), "*S", None), "C1,0,0", None).silent_by_rule


def test_decided_an_unanswered_breaker_is_kept_as_a_member():
    view = observe(observe(View(), "*S", None), "H", None)
    assert view.packet_open and view.role == "kept" and view.silent_by_rule
    assert not observe(view, "H", answer(b"8\r")).packet_open


def test_decided_a_frame_answered_inside_a_packet_ends_it():
    view = observe(observe(View(), "*S", None), "V100", answer(b"0\r"))
    assert not view.packet_open and view.role == "closes"


def test_a_taken_j_restarts_the_view_and_a_refused_mode_change_changes_nothing():
    view = observe(View(), "%+", answer(b"0\r"))
    assert view.checksums
    assert observe(view, "%-", answer(b"4\r")).checksums
    view = observe(observe(view, "*S", None), "J", answer(b"0\r"))
    assert not view.checksums and not view.packet_open and view.index == 0


def test_an_answer_that_came_late_is_the_frame_s_that_may_have_one():
    view = View()
    for body in ("*S", "C1,0,0", "V100", "C1,0,0"):
        view = observe(view, body, None, awaited=False)
    # `*S` and the `C` in the packet are answered by nothing: V100 is the first that may be
    owner = answered_late(view)
    assert owner is not None and owner.body == "V100"
    view = late(view, answer(b"0\r"))
    assert view is not None and not view.packet_open
    # the packet ended at V100: the `C` after it was no member, and is owed an answer
    assert [p.body for p in view.pending] == ["C1,0,0"] and view.answerable == 1
    view = late(view, answer(b"0\r"))
    assert view is not None and view.pending == () and late(view, answer(b"4\r")) is None


def test_an_awaited_answer_ends_the_pending_frames_chance_of_one():
    view = observe(observe(View(), "*S", None, awaited=False), "V100", None, awaited=False)
    assert view.answerable == 1
    view = observe(view, "*E1", answer(b"4,1\r"))
    assert view.pending == () and not view.packet_open


def test_frames_for_another_unit_change_nothing():
    view = View(addresses=frozenset({0, 7}))
    assert observe(view, "%+", answer(b"0\r"), 3) == view
    assert observe(view, "%+", answer(b"0\r"), 7).checksums       # the spindle shares it


def test_the_view_keeps_the_index_settings_status_and_position_as_read():
    # "17" reads alike in both forms a unit may write the index in: unknown until measured
    assert observe(View(), "@", answer(b"0,17\r")).index is None
    assert observe(View(), "@", answer(b"0,1F\r")).index == 31
    view = observe(View(index_form=Form.DECIMAL), "@", answer(b"0,17\r"))
    assert view.index == 17 and view.since_index == 0
    view = observe(observe(view, "V1000", answer(b"0\r")), "SW0,01", answer(b"0\r"))
    assert view.since_index == 2
    assert ("V", "1000") in view.modal and ("0", "01") in view.status
    view = observe(observe(view, "P", answer(b"0,1,2,3\r")), "SR6", answer(b"0,40\r"))
    assert view.position == ("1", "2", "3") and view.moving is True
