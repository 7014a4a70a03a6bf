"""A unit that restarts by itself, as the guard sees it (conformance/link/safety.py with
the envelope's trail): the power-on counters (spec 9: position 0) where the frames say
otherwise, or after frames went unanswered (spec 2: bytes are lost while a unit
restarts) when the axes had moved; a restart the suite caused (J, the rig's power-on) or
a checksum mode that outlived the silence (spec 6, 9) is none. Once seen, the case ends,
the counters count from wherever the axes stopped on their trail, and no frame that can
move goes out until the axes are located again. The envelope is ±1500 full steps;
every figure is worked out from the spec."""

from __future__ import annotations

import pytest

from conformance.link.envelope import Span
from conformance.link.framing import parse_response
from conformance.link.liveness import SILENCE_LIMIT, TargetNotResponding
from conformance.link.safety import EmulatorGuard, Guard
from conformance.link.stops import SafetyStop, UnitRestarted
from gve_fixtures.profile import load_profile
from tests.conformance.link.told import told

MS = 1_000_000


def guard(profile: str = "GVE84-100") -> Guard:
    g = Guard(load_profile(profile), 0, max_travel=1500, allow_destructive=True)
    g.envelope.origin({0: 0, 1: 0, 2: 0})
    return g


def answer(text: str | None, summed: bool = False):
    return None if text is None else parse_response(text.encode() + b"\r", summed=summed)


def sent(g: Guard, body: str, reply: str | None = "0", *, summed: bool = False) -> None:
    """``body`` passes the guard, goes out and gets ``reply`` (None: no answer), booked
    and counted as the link books and counts them."""
    g.check(body)
    r = answer(reply, summed)
    told(g, body, r)


def out_to(g: Guard, x: int) -> None:
    """X moved to ``x`` and shown at rest there by a read."""
    sent(g, f"L{x},0,0")
    sent(g, "SR6", "0,00")
    sent(g, "PF", f"0,{x},0,0")


def x(g: Guard) -> Span:
    return g.envelope.reach()[0]


def power_on_facts(g: Guard, index: int = 1) -> None:
    """The other power-on facts of spec 9 read: ST0..ST6 00, the index counting from 0."""
    for n in range(7):
        sent(g, f"SR{n}", "0,00")
    sent(g, "@", f"0,{index}")


def test_power_on_counters_where_the_frames_say_otherwise_are_a_restart():
    g = guard()
    sent(g, "L1500,0,0")
    power_on_facts(g)                   # ST6 too: the restart's own idle, RUN = 0
    with pytest.raises(UnitRestarted) as told:
        sent(g, "PF", "0,0,0,0")        # the frames say 1500: the power-on counters
    assert "restarted by itself: PF read 0,0,0" in str(told.value)
    # it stopped anywhere the vector took it; counter 0 is there, not where the run began
    assert x(g) == Span(0, 1500) and g.lost
    assert "X 0..1500, Y 0, Z 0" in str(g.restarts[0])
    with pytest.raises(SafetyStop, match="no motion"):
        g.check("L-1,0,0")
    sent(g, "SR6", "0,00")              # what cannot move still goes out
    sent(g, "L0,0,0")
    sent(g, "PF", "0,0,0,0")            # the same counters again: no second restart
    assert len(g.restarts) == 1


def test_a_restart_where_the_axes_stood_still_keeps_them_known():
    g = guard()
    out_to(g, 700)
    sent(g, "SR6", None)                # deaf: restarting
    with pytest.raises(UnitRestarted):
        sent(g, "PF", "0,0,0,0")
    assert x(g) == Span(700, 700) and not g.lost
    assert "the run went on from there" in str(g.restarts[0])
    # counter 0 is X at 700, not where the run began: 900 more would be 1600
    assert "X could reach 700..1600" in _refused(g, "L900,0,0")
    g.check("L-700,0,0")                # the way back


def test_after_silence_power_on_counters_where_the_frames_also_end_at_zero_are_a_restart():
    g = guard()
    sent(g, "L1000,0,0")
    sent(g, "L-1000,0,0", "7")          # refused: busy (spec 5)
    sent(g, "SR6", None)                # a silence while X may be anywhere on 0..1000
    sent(g, "L-1000,0,0")               # accepted: nothing runs
    sent(g, "SR6", "0,00")
    with pytest.raises(UnitRestarted) as told:
        sent(g, "PF", "0,0,0,0")        # 0 where the frames end: the restart's 0 too
    assert "1 frame(s) went unanswered" in str(told.value)
    assert x(g) == Span(0, 1000) and g.lost


def test_bytes_that_are_no_readable_answer_are_no_restart_s_silence():
    """A unit that restarts is deaf and mute (spec 2): one that sent bytes the suite could
    not read as the answer (a `>` answered in one line where two were awaited; diff draws
    such frames) was there to send them."""
    g = guard()
    sent(g, "L1000,0,0")
    sent(g, "L-1000,0,0", "7")
    g.check(">")
    told(g, ">", parse_response(b"\x00zz\r", summed=False, lines=2))   # not the two of `>`
    sent(g, "L-1000,0,0")
    sent(g, "SR6", "0,00")
    sent(g, "PF", "0,0,0,0")
    assert not g.restarts and not g.lost


def test_the_same_reads_without_a_silence_are_no_restart():
    g = guard()
    sent(g, "L1000,0,0")
    sent(g, "L0,0,0")
    sent(g, "L-1000,0,0")
    sent(g, "SR6", "0,00")
    sent(g, "PF", "0,0,0,0")
    assert x(g) == Span(0, 0) and not g.restarts and not g.lost
    g.check("L1500,0,0")


@pytest.mark.parametrize("restart", ["J", "rig"])
def test_the_silence_of_a_restart_the_suite_caused_is_no_restart_of_its_own(restart):
    g = guard()
    out_to(g, 400)
    if restart == "J":
        sent(g, "J")                    # answered, then deaf for about 2 s (spec 2)
    else:
        g.restarted()                   # the rig cycled the power
    sent(g, "SR6", None)
    sent(g, "SR6", None)
    sent(g, "L-400,0,0")
    sent(g, "SR6", "0,00")
    sent(g, "PF", "0,-400,0,0")         # the counters the restart zeroed at 400
    assert x(g) == Span(0, 0) and not g.restarts


def test_a_checksum_mode_that_outlived_the_silence_shows_no_restart_came():
    g = guard()
    sent(g, "%+", "0,5C", summed=True)
    sent(g, "L1000,0,0", "0,5C", summed=True)
    sent(g, "L-1000,0,0", "7,63", summed=True)
    sent(g, "*E1", None)                # a frame the unit may leave unanswered
    sent(g, "L-1000,0,0", "0,5C", summed=True)   # summed: the mode is still on (spec 9)
    sent(g, "SR6", "0,00,8A", summed=True)
    sent(g, "PF", "0,0,0,0,8C", summed=True)
    assert not g.restarts and x(g) == Span(0, 0)


def test_counters_the_frames_cannot_explain_leave_the_axes_anywhere_either_way():
    """Not the power-on counters: no restart is said and the case goes on to judge what it
    read (a unit that moved by another amount is a fault of its own rule); the frames
    that led there are named, and nothing moves until the axes are located."""
    g = guard()
    sent(g, "L300,0,0")
    sent(g, "L0,0,0")
    sent(g, "PF", "0,450,0,0")          # moved otherwise, or by other means: no exception
    g.check_idle()                      # the case is not stopped for it
    assert not g.restarts and len(g.untracked) == 1
    said = str(g.untracked[0])
    assert "restart" not in said
    assert ("PF read 450,0,0 at rest where the frames since the last read that agreed put "
            "them at 300,0,0; the first frame it could not follow: L300,0,0 → 0 (frames: "
            "L300,0,0 → 0; L0,0,0 → 0; PF → 0,450,0,0)") in said
    # where the counter says (450), or 450 from anywhere the axis had been (0..300)
    assert x(g) == Span(450, 750) and g.lost
    assert "no motion: the position counters disagree" in _refused(g, "L-1,0,0")
    sent(g, "SR6", "0,00")              # what cannot move still goes out


@pytest.mark.parametrize("facts, why", [
    # nothing else read, no frame lost: a unit that moved by a wrong amount reads 0 too
    ([("SR6", "0,00")], "ST0, ST1, ST2, ST3, ST4, ST5, the index (@) not read since"),
    # a status word the power-on would have cleared
    ([("SR2", "0,2B"), ("SR6", "0,00")], "ST2 read 2B"),
    # an index that counted on from before
    ([("SR6", "0,00"), ("@", "0,57")], "@ read 57 after 3 frame(s) since"),
])
def test_power_on_counters_alone_are_no_restart(facts, why):
    """Counters 0 where the frames put the axes elsewhere, without the other power-on facts
    of spec 9 seen (or with one contradicted): no restart is said. The case is not stopped
    and judges what it read; the guard names the frame it could not follow, and nothing
    moves until the axes are located."""
    g = guard()
    sent(g, "L480,0,0")
    for body, reply in facts:
        sent(g, body, reply)
    sent(g, "PF", "0,0,0,0")            # no exception: the case goes on
    g.check_idle()
    assert not g.restarts and len(g.untracked) == 1
    said = str(g.untracked[0])
    assert "restarted" not in said
    assert f"but no restart: {why}" in said
    assert "the first frame it could not follow: L480,0,0 → 0" in said
    assert g.lost and "no motion" in _refused(g, "L-1,0,0")


def test_facts_read_before_the_frames_were_lost_are_the_units_from_before():
    """An index read before frames went unanswered counts from before a restart that
    came with the silence: it does not say the unit did not restart."""
    g = guard()
    sent(g, "@", "0,121")
    sent(g, "L480,0,0")
    sent(g, "SR6", None)                # deaf: restarting
    sent(g, "SR6", "0,00")
    with pytest.raises(UnitRestarted):
        sent(g, "PF", "0,0,0,0")
    assert len(g.restarts) == 1 and not g.untracked


def test_power_on_counters_with_the_checksum_mode_still_on_are_no_restart():
    g = guard()
    sent(g, "%+", "0,5C", summed=True)
    sent(g, "L480,0,0", "0,5C", summed=True)
    for n in range(7):
        sent(g, f"SR{n}", "0,00,E8", summed=True)
    sent(g, "@", "0,3,E8", summed=True)
    sent(g, "PF", "0,0,0,0,70", summed=True)      # summed: the mode outlived it
    assert not g.restarts and "the checksum mode is on" in str(g.untracked[0])


def test_the_case_is_told_once_and_the_sessions_own_frames_go_on():
    g = guard()
    out_to(g, 200)
    sent(g, "SR6", None)
    with g.own_frames():                # the known state sees it: no exception there
        sent(g, "PF", "0,0,0,0")
        g.check("L-200,0,0")            # the axes stood still: known
    with pytest.raises(UnitRestarted):
        g.check("SR6")                  # the case's first frame is stopped for it
    g.check("SR6")                      # once


def test_the_rigs_eyes_locate_the_axes_and_motion_may_go_on():
    g = guard()
    sent(g, "L1500,0,0")
    power_on_facts(g)
    with pytest.raises(UnitRestarted):
        sent(g, "PF", "0,0,0,0")
    g.locate({0: 1010, 1: 0, 2: 0}, {0: 0, 1: 0, 2: 0})
    assert x(g) == Span(1010, 1010) and not g.lost
    assert "located them at X 1010, Y 0, Z 0" in str(g.restarts[0])
    assert "X could reach 1010..1510" in _refused(g, "L500,0,0")
    sent(g, "L-1010,0,0")               # back where the run began: counter -1010 there
    sent(g, "SR6", "0,00")
    sent(g, "PF", "0,-1010,0,0")
    assert x(g) == Span(0, 0)


def test_a_unit_that_restarts_is_heard_again_before_it_is_given_up():
    g = guard()
    for i in range(SILENCE_LIMIT + 2):  # frames 0.25 s apart in virtual time
        told(g, None, None, i * 250 * MS)
    assert g.responding is False and not g.liveness.dead     # silent for 1.25 s: restarting
    told(g, None, answer("0"), 3500 * MS)
    assert g.responding
    silent = []
    with pytest.raises(TargetNotResponding):
        for i in range(20):
            silent.append(i * 250)
            told(g, None, None, (4000 + i * 250) * MS)
    assert silent[-1] == 2 * 2000          # twice the restart time (spec 2: about 2 s)


def test_the_emulators_guard_gives_up_after_the_frames_alone():
    g = EmulatorGuard(load_profile("GVE84-100"), 0)
    with pytest.raises(TargetNotResponding):
        for i in range(SILENCE_LIMIT):
            told(g, None, None, i * MS)


def _refused(g: Guard, body: str) -> str:
    with pytest.raises(SafetyStop) as err:
        g.check(body)
    return str(err.value)
