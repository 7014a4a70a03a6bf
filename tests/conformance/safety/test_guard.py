"""The guard's other duties: destructive frames, other addresses, raw bytes framed as a
unit frames them (spec 3), Ctrl-C, silence, the operator's confirmation, timeouts."""

from __future__ import annotations

import pytest

from conformance.link.envelope import Outcome, point
from conformance.link.framing import HostFramer, parse_response
from conformance.link.liveness import TargetNotResponding
from conformance.link.safety import EmulatorGuard, Guard
from conformance.link.signals import Interrupted, StopSignals
from conformance.link.stops import SafetyStop
from gve_fixtures.profile import load_profile
from tests.conformance.link.told import told


def guard(profile: str = "GVE84-100", *, destructive: bool = False, travel: int = 500,
          interrupts: StopSignals | None = None) -> Guard:
    return Guard(load_profile(profile), 0, max_travel=travel,
                 allow_destructive=destructive, interrupts=interrupts)


@pytest.mark.parametrize("body", ["J", "WX,-100,100,10,100", "WX-100,100,10,100", "EW01,00",
                                  "EFW30,1.5", "EUW40,7", "ew01,00"])
def test_destructive_frames_need_permission(body):
    with pytest.raises(SafetyStop, match="--allow-destructive"):
        guard().check(body)


def test_eeprom_writes_go_only_to_bytes_backed_up():
    g = guard(destructive=True)
    g.eeprom.found({0x30: 0, 0x31: 0, 0x32: 0})
    with pytest.raises(SafetyStop, match="EEPROM 33 not backed up"):
        g.check("EFW30,1.5")                # four bytes: 30..33
    g.check("EW31,00")
    with pytest.raises(SafetyStop, match="not backed up"):
        g.check("EWzz,00")                  # which byte? not written
    assert g.eeprom.written == {0x31}


def test_motion_and_writes_for_another_address_are_refused():
    g = guard(destructive=True)
    g.eeprom.found(dict.fromkeys(range(256), 0))
    for body in ("L1,0,0", "G", "EW01,00"):
        with pytest.raises(SafetyStop, match="address 3"):
            g.check(body, 3)
    g.check("V2000", 3)                     # harmless elsewhere
    spindle = guard("GVE114-500", destructive=True)
    spindle.eeprom.found({1: 0})
    spindle.check("EW01,00", 7)             # the GVE114's own EEPROM, through address 7


def test_raw_bytes_are_framed_as_a_unit_frames_them():
    g = guard()
    framer = HostFramer()
    assert framer.frames(b"noise!0L1") == []
    frames = framer.frames(b"00,0,0\r!0V1!0L601,0,0\r\n")   # a '!' restarts the frame
    assert [f.text for f in frames] == ["L100,0,0", "L601,0,0"]
    with pytest.raises(SafetyStop):
        g.check_frames(frames, summed=False)
    # with the checksum mode unknown, "L400,0,10" may be z = 10 or a checksum: both judged
    (f,) = HostFramer().frames(b"!0L400,0,10\r")
    assert f.bodies(None) == ["L400,0,10", "L400,0"]
    g.check_frames([f], summed=None)
    with pytest.raises(SafetyStop):
        g.check_frames(HostFramer().frames(b"!0L400,0,600\r"), summed=None)


def test_in_checksum_mode_a_members_last_field_is_its_checksum_on_every_profile():
    # the GVE114 reads !0C682,151,0,7F in checksum mode as C682,151,0 with checksum 7F
    # (spec 6): the 7F is not an A component the guard cannot bound
    g = guard("GVE114-500", destructive=True, travel=1000)
    (f,) = HostFramer().frames(b"!0C682,151,0,7F\r")
    g.check_frames([f], summed=True)
    with pytest.raises(SafetyStop, match="axis A"):
        g.check_frames([f], summed=False)           # with the mode off it is A = 7F
    # a frame that may set the mode makes every reading count for the frames after it
    with pytest.raises(SafetyStop, match="axis A"):
        g.check_frames(HostFramer().frames(b"!0%-,CF\r!0C682,151,0,7F\r"), summed=True)
    with pytest.raises(SafetyStop, match="axis A"):
        g.check_frames(HostFramer().frames(b"!0J\r!0C682,151,0,7F\r"), summed=True)


def test_after_ctrl_c_only_the_sessions_own_frames_go_and_never_motion():
    interrupts = StopSignals()
    g = guard(interrupts=interrupts)
    interrupts.signal()
    with pytest.raises(Interrupted):
        g.check("SR0")
    with g.emergency():
        g.check("H")                        # the emergency stop goes first
    interrupts.handle()
    with pytest.raises(Interrupted):
        g.check("SR0")                      # still no case frame
    with g.own_frames():
        g.check("SW0,00")
        with pytest.raises(SafetyStop, match="no motion after Ctrl-C"):
            g.check("L0,0,1")
    interrupts.signal()
    with g.own_frames(), pytest.raises(Interrupted):
        g.check("SW1,00")                   # a new signal stops the restorations too


def test_consecutive_silences_give_the_target_up():
    g = guard()
    garbage = parse_response(b"\x00zz\r", summed=False)
    for r in (None, garbage, None):
        told(g, None, r)
    told(g, None, parse_response(b"0\r", summed=False))   # an answer: the count starts again
    for r in (None, None, garbage):
        told(g, None, r)
    with pytest.raises(TargetNotResponding, match="4 frames unanswered"):
        told(g, None, None)
    with pytest.raises(TargetNotResponding):
        g.check("SR0")                      # nothing more goes out


def test_the_operator_confirms_the_first_motion_once():
    asked = []
    g = guard()
    g.before_motion = lambda: asked.append(1)
    g.check("SR0")
    g.check("L0,0,0")                       # moves nothing
    assert asked == []
    g.check("L10,0,0")
    g.check("L20,0,0")
    assert asked == [1]
    no = guard()
    no.before_motion = lambda: False
    no.check("G")                           # nothing queued: G moves nothing
    no.check("R")                           # nothing saved: neither does R
    with pytest.raises(SafetyStop, match="not confirmed"):
        no.check("C1,0,0")
    no.accepted("H", parse_response(b"8\r", summed=False))
    no.envelope.vector([point(5), point(0), point(0)], Outcome.ACCEPTED, stand_alone=False)
    with pytest.raises(SafetyStop, match="not confirmed"):
        no.check("G")                       # now it would resume a vector


def test_halt_waits_for_the_longest_stop_the_envelope_allows():
    g = guard(travel=2000)
    # braking over the whole width (4000 steps) at A1 (1000 steps/s²): sqrt(2·4000/1000)
    assert g.stop_seconds() == pytest.approx(8 ** 0.5)
    assert g.answer_seconds("H") == pytest.approx(2 * 8 ** 0.5)
    assert g.answer_seconds("WY,-2000,1000,200,100") == pytest.approx(2 + 2 + 4 * 8 ** 0.5)
    assert g.answer_seconds("V100") is None
    # a travel no unit takes is not waited for until the clock runs out (ten minutes)
    assert g.answer_seconds("w,99999999999999,+1,,900") == 600
    assert g.answer_seconds("WX,-99999999999999,1,1,1") == 600


def test_a_power_cycle_by_the_rig_is_booked_as_a_restart():
    """The counters start again at 0 and the axes stay: a later PF of 0 is read as where
    the axis already was, not as a move back to where the run began."""
    g = guard()
    g.envelope.origin({0: 0, 1: 0, 2: 0})                  # the counters as found
    g.accepted("L300,0,0", parse_response(b"0\r", summed=False))
    g.accepted("SR6", parse_response(b"0,00\r", summed=False))  # it ended
    g.restarted()
    g.accepted("PF", parse_response(b"0,0,0,0\r", summed=False))
    assert g.envelope.position()[0] == 300
    with pytest.raises(SafetyStop, match="beyond the envelope"):
        g.check("L300,0,0")                               # 600 > 500


def test_a_vector_may_be_asked_about_before_it_is_drawn_again():
    # a Hypothesis machine draws another vector instead of ending COULD-NOT-TEST
    g = guard(travel=500)
    assert g.fits("C300,0,0") and g.farthest("C300,0,0") == 300
    g.accepted("C300,0,0", parse_response(b"0\r", summed=False))
    assert not g.fits("C300,0,0") and g.farthest("C300,0,0") == 600
    assert g.fits("C-300,0,0") and g.farthest("V1000") == 300
    assert g.farthest("Cx,0,0") == float("inf")


def test_the_emulator_has_no_envelope():
    g = EmulatorGuard(load_profile("GVE84-100"), 0)
    assert g.fits("C2147483647,0,0")


def test_silence_inside_an_open_packet_is_no_silence():
    g = guard()
    g.check("*S")
    told(g, "*S", None)
    for _ in range(6):
        told(g, "C1,0,0", None)             # members: the unit answers nothing until *E
    assert g.responding
    g.check("*E6")
    told(g, "*E6", None)
    for _ in range(2):
        told(g, None, None)
    with pytest.raises(TargetNotResponding, match="4 frames unanswered"):
        told(g, None, None)


def test_an_unanswered_breaker_leaves_the_packet_open():
    # that H closes a packet is our reading [D]: a unit may take it as a member
    g = guard()
    g.accepted("*S", None)
    g.accepted("H", None)
    assert g.packet_open
    g.accepted("H", parse_response(b"8\r", summed=False))
    assert not g.packet_open


def test_the_bytes_named_are_those_of_the_silence_that_gave_up():
    g = guard()
    told(g, None, parse_response(b"!0C1,0,167\r", summed=False))    # not an answer
    told(g, None, parse_response(b"0\r", summed=False))
    for _ in range(3):
        told(g, None, None)
    with pytest.raises(TargetNotResponding) as err:
        told(g, None, None)
    assert "not an answer" not in str(err.value)
