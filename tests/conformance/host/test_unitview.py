"""What a unit executed, read from the wire (spec 7, 8, 10.1): the oracle's input."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from conformance.host.unitview import UnitView
from conformance.protocol.view import View, observe
from conformance.protocol.wire import parse_response
from tests.conformance.host.records import PROFILE, UNITS, Wire
from tests.conformance.protocol.test_view import ANSWERS, FRAMES


def booked(w: Wire) -> UnitView:
    view = UnitView(PROFILE, 0)
    for ex in w.rec.exchanges:
        view.apply(ex, UNITS)
    return view


def test_accepted_vectors_with_the_settings_they_run_under():
    w = Wire()
    w.frame(b"!0V2000", 0)
    w.frame(b"!0L100,0,0", 10)
    w.frame(b"!0L200,0,0", 20, answer=b"1\r")          # queue full: not executed
    w.frame(b"!0V3000", 30, answer=b"4\r")             # refused: V stays 2000
    w.frame(b"!0C0,5,0", 40, answer=b"8\r")            # OK while interrupted (spec 4)
    w.frame(b"!0L0,0,0", 50)                           # the wait idiom moves nothing
    steps = booked(w).executed
    assert [(s.kind, s.values) for s in steps] == [("L", (100, 0, 0)), ("C", (0, 5, 0))]
    assert all(dict(s.modal)["V"] == 2000 for s in steps)


def test_a_packet_commits_only_on_its_answer_0():
    w = Wire()
    for raw in (b"!0*S", b"!0C1,0,0", b"!0B500", b"!0C2,0,0"):
        w.frame(raw, len(w.rec.exchanges), answer=None)
    w.frame(b"!0*E3", 5, answer=b"2,3\r")               # refused: nothing committed
    for raw in (b"!0*S", b"!0C1,0,0", b"!0B500", b"!0C2,0,0"):
        w.frame(raw, 10 + len(w.rec.exchanges), answer=None)
    w.frame(b"!0*E3", 20, answer=b"0,3\r")
    steps = booked(w).executed
    assert [s.values for s in steps] == [(1, 0, 0), (2, 0, 0)]
    assert dict(steps[0].modal)["B"] == PROFILE.reset.B and dict(steps[1].modal)["B"] == 500


def test_checksum_mode_follows_the_units_answers():
    w = Wire()
    w.frame(b"!0%+", 0, answer=b"0,5C\r")
    view = booked(w)
    assert view.checksums
    w.frame(b"!0%-,CF", 10, answer=b"0\r", checksums=True)
    assert not booked(w).checksums


def test_j_resets_what_the_unit_remembers():
    w = Wire()
    w.frame(b"!0V2000", 0)
    w.frame(b"!0J", 10)
    view = booked(w)
    assert view.modal["V"] == PROFILE.reset.V
    assert view.executed[-1].kind == "J" and view.deaf_until > 0


def test_the_interrupt_input_the_host_enabled():
    w = Wire()
    w.frame(b"!0SW2,00", 0)
    w.frame(b"!0SW0,04", 10)                           # INTR2 on I1 bit 2 (GVE84)
    assert booked(w).interrupt_input() == (1, 2, 0)
    w.frame(b"!0SW0,08", 20)                           # bit 3: no input behind it
    assert booked(w).interrupt_input() is None


def test_a_restart_in_checksum_mode_leaves_the_mode_lapsed_until_the_host_sets_it():
    w = Wire()
    w.frame(b"!0%+", 0, answer=b"0,5C\r")
    view = booked(w)
    assert view.checksums
    view.power_on(0)
    assert not view.checksums and view.lapsed
    view.power_on(0)                  # off already: nothing lapses a second time
    assert not view.lapsed


def test_the_open_packet_and_the_mode_are_the_view_s_of_the_wire():
    """Decided (docs/decisions.md, "one view of the unit"): an answered `*S` opens no
    packet, and a frame answered inside one ends it; the oracle reads both from the view."""
    w = Wire()
    w.frame(b"!0*S", 0, answer=b"4\r")
    assert booked(w).packet is None
    w.frame(b"!0*S", 10, answer=None)
    w.frame(b"!0C1,0,0", 20, answer=None)
    view = booked(w)
    assert [f.body for f in view.packet or []] == ["C1,0,0"] == list(view.wire.packet or ())
    w.frame(b"!0V100", 30)                             # answered: the unit took no member
    view = booked(w)
    assert view.packet is None and not view.wire.packet_open
    w.frame(b"!0*E1", 40, answer=b"4,0\r")
    assert booked(w).executed == []


@settings(max_examples=150, deadline=None)
@given(st.lists(st.tuples(st.sampled_from(FRAMES), st.sampled_from(ANSWERS)), max_size=20))
def test_the_oracle_keeps_no_packet_or_mode_of_its_own(exchanges):
    """Whatever the wire, the oracle's open packet and checksum mode are those of the one
    view fed the same frames and answers (protocol/view.py)."""
    w = Wire()
    wire = View()
    for i, (body, raw) in enumerate(exchanges):
        w.frame(b"!0" + body.encode(), 10 * i, answer=raw)
        wire = observe(wire, body, None if raw is None else
                       parse_response(raw, summed=wire.summed_after(body)))
    view = booked(w)
    assert (view.packet is not None) == wire.packet_open
    assert view.checksums == wire.checksums
    assert len(view.packet or []) == len(wire.packet or ())
