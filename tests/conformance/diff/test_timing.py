"""The timing a pair is run with: exact between two sides in virtual time, the real-time
allowance (latency, slack, cut) as soon as one side is not."""

import pytest

from conformance.diff.engine import Pair
from conformance.diff.grammar import Grammar, Options
from conformance.diff.sides import RoundTrip, Side
from conformance.diff.timing import RealTime, Timing
from conformance.link.framing import frame
from conformance.link.signals import StopSignals
from conformance.targets import parse_target
from tests.emulator.process import Emulator
from tests.usb_relay import UsbRelay

MS = 1_000_000


def sides() -> tuple[Side, Side]:
    return Side(parse_target("emu:GVE84-100")), Side(parse_target("emu:GVE84-100"))


def test_two_virtual_sides_are_compared_exactly():
    target, reference = sides()
    p = Pair(target, reference, target.target.profile)
    assert type(p.timing) is Timing and p.exact and p.timing.repeatable
    reply = RoundTrip(b"H", b"0\r", 0, 200 * MS, None)
    p.timing.retimed("H", reply)
    assert p.timing.allowance("P", reply, reply) == (False, 0)


def test_in_real_time_a_course_change_while_moving_widens_later_readings():
    """The latency is the slowest immediate answer so far (an H answers when stopped: not
    a latency); what changes a running motion's course adds it to the readings while it
    runs, what stops it short to the positions at rest too; a setting at rest adds
    nothing."""
    t = RealTime(*sides())
    assert not t.exact and not t.repeatable

    def sent(command: str, took_ms: int) -> tuple[int, int, int]:
        reply = RoundTrip(command.encode(), b"0\r", 0, took_ms * MS, None)
        t.retimed(command, reply)
        return t.latency_ns // MS, t.slack_ns // MS, t.cut_ns // MS

    t.idle_since = None                              # the reference was moving
    assert sent("V", 2) == (2, 0, 0)
    assert sent("XM", 1) == (2, 2, 0)
    assert sent("H", 200) == (2, 4, 2)
    t.idle_since = 5                                 # at rest since
    assert sent("XM", 3) == (3, 4, 2)
    assert not t.lost and sent("D", 1) == (3, 4, 2) and t.lost
    t.begin()                                        # a new example forgets it all
    assert (t.latency_ns, t.slack_ns, t.cut_ns, t.lost, t.idle_since) == (0, 0, 0, False, 0)


def test_in_real_time_an_h_answered_late_was_taken_as_late_as_its_answer_shows():
    """An H answers when stopped: the target took it up to as much later than the
    reference as its answer came later (the line at that frame, which the immediate
    answers before it do not show); never less late than the latency."""
    t = RealTime(*sides())
    t.retimed("V", RoundTrip(b"V", b"0\r", 0, 2 * MS, None))
    t.idle_since = None                              # the reference was moving
    braked = RoundTrip(b"H", b"8\r", 0, 50 * MS, None)
    t.retimed("H", RoundTrip(b"H", b"8\r", 0, 71 * MS, None), braked)
    assert (t.slack_ns // MS, t.cut_ns // MS) == (21, 21)
    t.retimed("H", RoundTrip(b"H", b"8\r", 0, 50 * MS, None), braked)
    assert (t.slack_ns // MS, t.cut_ns // MS) == (23, 23)


def test_in_real_time_a_rig_input_was_set_as_late_as_the_rig_s_ok_came():
    """A rig input is set over the rig's own channel: the target's unit may have seen it
    as late as the rig's `ok` came, however quick the line's answers were; that channel's
    time is no round trip of the line (the band's jitter does not take it)."""
    t = RealTime(*sides())
    t.retimed("V", RoundTrip(b"V", b"0\r", 0, 2 * MS, None))
    t.idle_since = None                              # the reference was moving
    t.retimed("input", RoundTrip(b"", b"ok", 5 * MS, 17 * MS, None))
    assert (t.latency_ns // MS, t.slack_ns // MS, t.cut_ns // MS) == (2, 12, 12)
    assert len(t.trips) == 1
    t.retimed("input", RoundTrip(b"", b"", 20 * MS, 21 * MS, None))   # the rig lost
    assert (t.slack_ns // MS, t.cut_ns // MS) == (14, 14)


def test_the_line_band_is_the_target_s_measured_line_widened_by_the_example():
    """Exact in virtual time; in real time from the round trip the target's session
    measured, its min and max widened by the example's immediate answers (not an H's)."""
    target, reference = sides()
    assert Timing(target, reference).line().exact
    t = RealTime(target, reference)
    target.open()
    target.link.round_trip = {"min_ms": 1.0, "median_ms": 3.0, "max_ms": 4.0,
                              "byte_ms": 0.5, "bytes_ms": 1.0}
    assert t.line().seconds == 4.5e-3                # 1 one way + 3 jitter + 0.5 a byte
    t.retimed("V", RoundTrip(b"V", b"0\r", 0, 6 * MS, None))
    t.retimed("H", RoundTrip(b"H", b"8\r", 0, 300 * MS, None))
    assert abs(t.line().seconds - 6.5e-3) < 1e-12     # jitter 6 - 1 (the session's min)
    t.retimed("V", RoundTrip(b"V", b"0\r", 0, 5 * MS, None))
    assert abs(t.line().seconds - 2.5e-3) < 1e-12     # two of its own: jitter 6 - 5
    t.begin()
    assert t.line().seconds == 4.5e-3
    target.close_example()


@pytest.mark.pty
def test_in_real_time_an_h_the_line_delivers_late_is_judged_by_its_own_answer():
    """A correct unit behind a line that delivers one frame late, the H (20 ms: the host
    under load as it sent it, which no round trip before it shows): the unit brakes from
    20 steps farther, and its answer comes as much later than the reference's. The read
    at rest after it is judged with how late that answer shows the H may have been taken,
    not only with the latency of the frames before it: no disagreement."""
    emu = Emulator("--model", "GVE84-100", "--pty")
    relay = UsbRelay(emu.first, latency_ms=1, jitter_ms=0, hold=frame("H", 0, False),
                     hold_ms=20)
    target = parse_target(f"serial:{relay.path}", profile="GVE84-100")
    try:
        target.preflight()
        session = target.begin(StopSignals())
        pair = Pair(Side(target, session), Side(parse_target("emu:GVE84-100")),
                    target.profile)
        steps = Grammar(target.profile, Options()).idiom(
            ["L400", "wait 0.1", "H", "wait 0.3", "PF"])
        out = pair.run(steps)
        session.finish()
    finally:
        target.close()
        relay.close()
        emu.stop()
    read = out.records[-1]
    assert read.step.body == "PF" and read.target is not None
    farther = read.target.response.decs()[0] - read.reference.response.decs()[0]
    assert farther >= 10, farther                     # the hold did delay the H
    assert out.disagreement is None, (read.target.answer, read.reference.answer)
