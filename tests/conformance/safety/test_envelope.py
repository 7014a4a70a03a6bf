"""The run's envelope, bookkeeping alone (conformance/link/envelope.py through the guard):
what a unit may do with what it accepted, from spec 5, 7, 10.1, 10.4, 10.5, 10.7. The
envelope is ±500 full steps here; every expected figure is worked out from the spec."""

from __future__ import annotations

import pytest

from conformance.link.envelope import Span
from conformance.link.framing import parse_response
from conformance.link.safety import Guard
from conformance.link.stops import SafetyStop
from gve_fixtures.profile import load_profile


def guard(profile: str = "GVE84-100", travel: int = 500) -> Guard:
    g = Guard(load_profile(profile), 0, max_travel=travel, allow_destructive=True)
    g.envelope.origin({0: 0, 1: 0, 2: 0})       # the run begins at counters 0
    return g


def answer(text: str):
    return None if text is None else parse_response(text.encode() + b"\r", summed=False)


def sent(g: Guard, body: str, reply: str | None = "0") -> None:
    """The frame passes the guard, goes out, and is answered ``reply``."""
    g.check(body)
    g.accepted(body, answer(reply))


def refused(g: Guard, body: str) -> str:
    with pytest.raises(SafetyStop) as err:
        g.check(body)
    return str(err.value)


def x(g: Guard) -> tuple[float, float]:
    s = g.envelope.reach()[0]
    return s.lo, s.hi


def test_a_vector_counts_whole_until_the_unit_shows_it_ended():
    g = guard()
    sent(g, "C300,0,0")
    assert "X could reach 0..600" in refused(g, "C300,0,0")    # 300 + 300 > 500
    sent(g, "SR6", "0,40")                                    # RUN: still on its way
    assert x(g) == (0, 300)
    sent(g, "SR6", "0,00")                                    # RUN = 0: it ended at 300
    assert x(g) == (300, 300)
    sent(g, "C-800,0,0")                                      # to -500: inside
    assert x(g) == (-500, 300)


def test_back_and_forth_costs_only_the_widest_swing():
    g = guard(travel=2)
    sent(g, "H", "8")
    for i in range(2048):
        sent(g, "C1,0,0" if i % 2 == 0 else "C-1,0,0")
    assert x(g) == (0, 1)


def test_counter_resets_do_not_reset_the_odometer():
    g = guard()
    sent(g, "L400,0,0")
    sent(g, "L0,0,0")                      # accepted: the L before it has ended (spec 10.1)
    sent(g, "N")                           # counters 0, the axis still 400 from the start
    sent(g, "NX-1000")
    assert "X could reach 400..600" in refused(g, "L200,0,0")
    sent(g, "L-900,0,0")                   # to -500: inside
    sent(g, "SR6", "0,00")
    sent(g, "PF", "0,-1900,0,0")           # counter -1900 = -1000 + (-900): physical -500
    assert x(g) == (-500, -500)


def test_a_set_counter_read_back_otherwise_is_a_counter_not_a_move():
    g = guard()
    sent(g, "L300,0,0")
    sent(g, "L0,0,0")                      # at rest at 300
    sent(g, "NX2147483647")
    # a 24-bit counter: 2^31 - 1 reads -1; no frame moved X, so X rests at 300 still
    sent(g, "PF", "0,-1,0,0")
    assert x(g) == (300, 300) and g.envelope.unheld == [0]
    sent(g, "L-300,0,0")                   # back where the run began, inside the envelope
    sent(g, "L0,0,0")
    sent(g, "PF", "0,-301,0,0")            # the counter anchored to the read: -1 - 300
    assert x(g) == (0, 0)


def test_without_a_counter_set_a_read_that_contradicts_the_frames_wins_nothing():
    g = guard()
    sent(g, "L300,0,0")
    sent(g, "L0,0,0")
    sent(g, "PF", "0,450,0,0")             # moved by other means, or restarted and moved on
    assert x(g) == (450, 750) and g.envelope.unheld == [] and g.lost


def test_a_halted_and_deleted_vector_leaves_the_axis_anywhere_on_it_until_read():
    g = guard()
    sent(g, "C400,0,0")
    sent(g, "H", "8")
    sent(g, "D")
    assert x(g) == (0, 400)
    assert "X could reach 0..600" in refused(g, "L200,0,0")   # from anywhere on 0..400
    sent(g, "PF", "0,123,0,0")             # nothing can move after D: it rests at 123
    assert x(g) == (123, 123)
    sent(g, "L377,0,0")                    # to 500 exactly


def test_a_kept_remainder_runs_to_where_the_queue_would_have_ended_moved_as_the_axes_moved():
    """K keeps what is left of the queue, however far it got: its run ends where the
    queue would have, shifted by every move the axes make before R. A read after K that
    tells how far it got (100 of 450) does not make the remainder count whole from there
    (100..550 would leave the envelope; a unit goes to 450)."""
    g = guard()
    sent(g, "C450,0,0")
    sent(g, "H", "8")
    sent(g, "K")                           # the save: what is left of 0..450
    sent(g, "PF", "0,100,0,0")             # halted at 100: 350 are left
    sent(g, "L0,0,-300")
    sent(g, "L0,0,300")
    sent(g, "SR6", "0,00")
    g.check("R")                           # within 100..450
    sent(g, "L-100,0,0")                   # the save's run moves with the axes: 0..350
    sent(g, "SR6", "0,00")
    sent(g, "R", "8")
    sent(g, "G")
    assert x(g) == (-100, 350)
    sent(g, "SR6", "0,00")
    sent(g, "PF", "0,350,0,0")             # where a unit rests: inside, and now known
    assert x(g) == (350, 350) and not g.restarts and not g.untracked


def test_a_packet_is_judged_whole_before_its_end_is_sent():
    g = guard()
    sent(g, "*S", None)
    for _ in range(4):
        sent(g, "C100,0,0", None)          # members: no answer, maybe committed as they come
    assert x(g) == (0, 400)
    refused(g, "C200,0,0")                 # a member that would make the packet 600
    sent(g, "*E4", "0,4")
    assert x(g) == (0, 400)
    sent(g, "*S", None)
    sent(g, "C100,0,0", None)
    assert "X could reach 0..600" in refused(g, "C100,0,0")
    # refused: nothing committed by our reading, but a unit may have committed the
    # member as it arrived (all-or-nothing is [D]), so it may have moved
    sent(g, "*E1", "2,1")
    assert x(g) == (0, 500)


def test_a_refused_packet_ends_where_it_began_or_where_it_leads_until_a_read_at_rest():
    g = guard()
    sent(g, "*S", None)
    sent(g, "C0,5,0", None)
    sent(g, "C0,5,0", None)
    sent(g, "*E4", "2,3")                  # refused: the members maybe taken as they came
    sent(g, "SR6", "0,00")                 # all ended: Y at 0 (not taken) or 10 (taken)
    assert g.envelope.reach()[1] == Span(0, 10) and g.envelope.position()[1] is None
    sent(g, "PF", "0,0,0,0")               # read at rest: not taken
    assert g.envelope.position() == [0, 0, 0]


def test_a_counter_set_where_the_axis_is_not_known_leaves_the_way_back_unknown():
    g = guard()
    sent(g, "*S", None)
    sent(g, "C0,5,0", None)
    sent(g, "*E2", "4,2")
    sent(g, "SR6", "0,00")
    sent(g, "NY-1205")                     # set at 0 or at 5: the counter no longer tells
    sent(g, "PF", "0,0,-1205,0")
    assert g.envelope.reach()[1] == Span(0, 5) and g.envelope.position()[1] is None


def test_gve54_vectors_are_in_the_micro_step_mode_and_positions_in_sixteenths():
    g = guard("GVE54", travel=100)         # 1600 sixteenths either side
    # the mode is not known yet: up to 8 sixteenths a step (M2)
    assert "X could reach 0..100.5 " in refused(g, "L201,0,0")
    sent(g, "MF")
    sent(g, "L1600,0,0")                   # 1600 sixteenths = 100 full steps
    sent(g, "L0,0,0")
    sent(g, "M4")
    assert "X could reach 100..100.25" in refused(g, "L1,0,0")
    sent(g, "L-400,0,0")                   # 400 quarter steps: back to 0
    assert g.excursion()[0] == (0, 100)


def test_a_reference_run_counts_its_whole_travel():
    g = guard()
    assert "Y could reach -600..50 " in refused(g, "WY,-600,1000,50,500")
    sent(g, "WY,-450,1000,50,500")         # to the switch within 450, back within 50
    assert g.envelope.reach()[1].lo == -450 and g.envelope.reach()[1].hi == 50


def test_an_unclear_answer_is_whichever_reaches_farther():
    g = guard()
    sent(g, "C300,0,0")
    sent(g, "D", None)                     # deleted or not: the vector may still run
    sent(g, "PF", "0,10,0,0")              # so a read tells nothing
    assert x(g) == (0, 300)
    sent(g, "L150,0,0", None)              # maybe accepted: counted from anywhere on 0..300
    assert x(g) == (0, 450)


def test_unreadable_numbers_in_a_motion_frame_are_unbounded():
    g = guard()
    refused(g, "L9999999999999,0,0")
    refused(g, "L1x,0,0")
    refused(g, "l600,0,0")                 # lower case: a lenient unit may take it
    sent(g, "L+5, 5,")                     # lenient readings stay bounded
    assert x(g) == (0, 5)


def test_a_packet_a_breaker_discards_may_have_been_committed_as_it_arrived():
    g = guard()
    sent(g, "*S", None)
    sent(g, "C0,200,0", None)
    sent(g, "C0,200,0", None)
    sent(g, "@", "0,3")                    # discards the packet (our reading [D]) ...
    # ... but a unit may have queued the members as they came (spec 7 is silent)
    assert g.envelope.reach()[1] == Span(0, 400)
    sent(g, "*S", None)
    sent(g, "C0,-50,0", None)
    sent(g, "*S", None)                    # a second *S restarts it: the same
    assert g.envelope.reach()[1] == Span(-50, 400)


def test_a_b_answered_while_a_packet_may_be_open_moves_nothing():
    """A unit that dropped the packet (a watchdog's reading) answers its B: a modal
    setting, no vector."""
    g = guard()
    sent(g, "*S", None)
    sent(g, "B200", "0")
    assert x(g) == (0, 0)
    sent(g, "L1,0,0")
    sent(g, "L0,0,0")
    assert g.envelope.position()[0] == 1


def test_a_save_given_back_may_still_be_held_and_run_again():
    """That `R` empties the save is a decision (spec 10.5 [D]): a unit that keeps it runs
    the remainder again after a second `R` and `G`, from where the first run ended. The
    envelope follows it; no `K` is then held that the known state must give back."""
    g = guard()
    sent(g, "C300,0,0")
    sent(g, "H", "8")
    sent(g, "K")                           # the save: what is left of 0..300
    sent(g, "PF", "0,100,0,0")             # halted at 100: 200 are left
    assert g.keep_held
    sent(g, "R", "8")
    sent(g, "G")
    sent(g, "SR6", "0,00")
    sent(g, "PF", "0,300,0,0")             # the save ran: 300
    assert not g.keep_held
    sent(g, "R", "8")                      # a unit that keeps its save: 200 more
    sent(g, "G")
    assert x(g)[1] >= 500
    sent(g, "SR6", "0,00")
    sent(g, "PF", "0,500,0,0")
    assert x(g) == (500, 500) and not g.restarts and not g.untracked
    assert "R" in refused(g, "R")          # a third run would leave the ±500 envelope


def test_a_counter_set_on_one_axis_with_a_halted_remainder_held_ends_nothing():
    # N<axis> is refused while RUN = 1 by our decision only: a unit may take it after H
    g = guard()
    sent(g, "C200,0,0")
    sent(g, "C200,0,0")
    sent(g, "H", "8")
    sent(g, "NY-5", "8")
    assert x(g) == (0, 400)                # still anywhere on the halted queue's way
    sent(g, "P", "8,60,-5")                # at rest where the halt left it, no contradiction
    assert not g.lost
    sent(g, "D", "8")                      # the remainder dropped where X stands
    sent(g, "PF", "8,60,-5,0")
    assert x(g) == (60, 60) and not g.lost


def test_run_clear_read_after_an_st6_write_does_not_end_the_queue():
    # a unit may store the RUN bit SW6 writes: 0 then tells nothing of the held vectors
    g = guard()
    sent(g, "C200,0,0")
    sent(g, "C200,0,0")
    sent(g, "SW6,80", "8")
    sent(g, "SR6", "8,80")
    assert x(g) == (0, 400)
    sent(g, "PF", "8,0,0,0")               # not taken for a read at rest
    assert not g.lost
    sent(g, "D", "8")
    sent(g, "SR6", "8,80")
    sent(g, "PF", "8,0,0,0")
    assert x(g) == (0, 0) and not g.lost
