"""What a unit executed, read from the wire (spec 7, 8, 10.1): the oracle's input."""

from __future__ import annotations

from conformance.host.unitview import UnitView
from tests.conformance.host.records import PROFILE, UNITS, Wire


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
    view = UnitView(PROFILE, 0)
    view.checksums = True
    view.power_on(0)
    assert not view.checksums and view.lapsed
    view.power_on(0)                  # off already: nothing lapses a second time
    assert not view.lapsed
