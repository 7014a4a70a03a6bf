"""Frames told a co-simulator ahead (conformance/link/ahead.py): a frame is told only when
the run's guard lets it through whatever the unit answers the frames told before it.
The property is checked against the guard itself: random frames, random answers (codes,
silences, bytes that are no answer, positions and status words read), and every frame
the copy admitted is one the guard lets through when it is sent after the frames before
it got those answers."""

from __future__ import annotations

import contextlib
from types import SimpleNamespace

import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from conformance.link.ahead import Ahead
from conformance.link.body import Body
from conformance.link.framing import frame, parse_response
from conformance.link.link import Link
from conformance.link.liveness import TargetNotResponding
from conformance.link.safety import Guard
from conformance.link.stops import SafetyStop, UnitRestarted
from conformance.protocol.catalogue import classes
from gve_fixtures.profile import load_profile
from tests.conformance.link.told import told

MOVE_NOTHING = classes(motion=False, own_speed=False, resumes=None, destructive=False,
                       eeprom=0)
POSITION_READS = classes(position=True)
TRAVEL = 300                                   # full steps either side: often reached

steps = st.integers(-250, 250)
vectors = st.builds(lambda k, a, b, c: f"{k}{a},{b},{c}", st.sampled_from("LC"), steps, steps,
                    steps)
bodies = st.one_of(
    vectors, vectors, vectors,
    st.sampled_from(["G", "R", "K", "D", "H", "J", "N", "*S", "*E", "SW6,00", "PF", "P",
                     "SR6", "F", "SR0", "@", "?", "V400", "M2"]),
    st.builds(lambda axis, v: f"N{axis}{v}", st.sampled_from("XYZ"), steps),
)
answers = st.one_of(
    st.none(),                                          # no answer
    st.sampled_from(["0", "5", "7", "8", "xx", "0,00", "0,40", "0,C0"]),
    st.builds(lambda a, b, c: f"0,{a},{b},{c}", steps, steps, steps),   # a position read
)


def guard(**kw) -> Guard:
    g = Guard(load_profile("GVE84-100"), 0, max_travel=TRAVEL, allow_destructive=True, **kw)
    g.envelope.origin({0: 0, 1: 0, 2: 0})
    return g


def link(g: Guard) -> SimpleNamespace:
    """What Ahead reads of a link: its guard, and whether its port takes frames ahead."""
    return SimpleNamespace(guard=g, takes_ahead=True, port=None)


def response(text: str | None):
    return None if text is None else parse_response(text.encode() + b"\r", summed=False)


def sent(g: Guard, body: str, text: str | None) -> bool:
    """The frame passes the guard (else SafetyStop) and is answered ``text``; False when
    its answer ended the case (a read that shows a restart)."""
    g.check(body)
    r = response(text)
    try:
        told(g, body, r)
    except TargetNotResponding:
        g.liveness.dead, g.liveness.silences = False, 0   # the silence count is not the envelope's
    except UnitRestarted:
        return False
    return True


@given(st.lists(st.tuples(bodies, answers), max_size=12),
       st.lists(st.tuples(bodies, answers), min_size=1, max_size=12))
# a read at rest that contradicts the bookkeeping moves it, and may end the case: only
# what sets nothing moving is told after it
@example([], [("PF", "0,250,0,0"), ("L200,0,0", "0")])
@example([], [("PF", "0,250,0,0"), ("SR0", "0,00")])
# a packet closed by a breaker the unit answered: its next C is a vector, not a member
@example([], [("*S", None), ("@", "0,1"), ("C200,0,0", "0"), ("L200,0,0", "0")])
@settings(max_examples=400, deadline=None, derandomize=True)
def test_a_frame_told_ahead_is_let_through_whatever_the_answers_before_it(before, told):
    g = guard()
    for body, text in before:                  # the run so far, answered
        with contextlib.suppress(SafetyStop):
            sent(g, body, text)
    ahead = Ahead(link(g))
    admitted = [(body, text) for body, text in told if ahead.admit(frame(body, 0, False), 1.0)]
    assert admitted == told[:len(admitted)]    # a prefix: the first refused ends them
    ended = False
    for body, text in admitted:                # then sent, each answered anyhow
        if ended:
            # a case ended by an answer is told only what sets nothing moving after it
            assert Body.parse(body).name in MOVE_NOTHING
            continue
        ended = not sent(g, body, text)        # SafetyStop if the guard refused it


def test_judging_ahead_changes_nothing_of_the_guard():
    g = guard()
    sent(g, "C100,0,0", "0")
    before = (g.envelope.reach(), list(g.envelope.seen), dict(vars(g.eeprom)), g.packet_open,
              list(g.since))
    ahead = Ahead(link(g))
    for body in ("*S", "C200,0,0", "C200,0,0", "*E", "EW05,AA"):
        ahead.admit(frame(body, 0, False), 1.0)
    assert (g.envelope.reach(), list(g.envelope.seen), dict(vars(g.eeprom)),
            g.packet_open, list(g.since)) == before


def test_after_a_position_read_only_what_sets_nothing_moving_is_told():
    # a read that contradicts the bookkeeping moves it, or shows a restart (which ends
    # the case): what may move the axes waits for its answer, as the guard's own frames
    # told ahead do (Guard.told_ahead)
    ahead = Ahead(link(guard()))
    assert ahead.admit(frame("SR0", 0, False), 1.0)
    assert ahead.admit(frame("PF", 0, False), 1.0)
    assert ahead.admit(frame("P", 0, False), 1.0)
    assert ahead.admit(frame("V400", 0, False), 1.0)
    assert not ahead.admit(frame("L1,0,0", 0, False), 1.0)
    assert not ahead.admit(frame("SR6", 0, False), 1.0)     # the first refused ends them
    assert len(ahead.frames) == 4


def test_a_frame_the_guard_refuses_is_not_told():
    ahead = Ahead(link(guard()))
    assert ahead.admit(frame("L200,0,0", 0, False), 1.0)
    # the first may have taken the axis to 200: 200 more leaves the envelope
    assert not ahead.admit(frame("L200,0,0", 0, False), 1.0)
    assert not ahead.admit(frame("L300,0,0", 1, False), 1.0)   # another unit's: never


def test_motion_not_confirmed_yet_is_not_told_and_nobody_is_asked():
    asked = []
    g = guard()
    g.before_motion = lambda: asked.append(1) or True
    assert not Ahead(link(g)).admit(frame("L1,0,0", 0, False), 1.0)
    assert asked == [] and g.motion_confirmed is None


@pytest.mark.parametrize("data", [b"junk!0SR0\r", b"!0SR0", b"!0SR0\r!0L1,0,0"])
def test_only_whole_frames_are_told(data):
    assert not Ahead(link(guard())).admit(data, 1.0)


@given(st.lists(st.tuples(bodies, answers), max_size=12),
       st.lists(st.tuples(bodies, answers), min_size=1, max_size=12))
@example([], [("L200,0,0", "0"), ("L200,0,0", "0")])
@example([], [("PF", "0,250,0,0"), ("L200,0,0", "0"), ("SR0", "0,00")])
@example([], [("PF", "0,250,0,0"), ("SW6,00", "0")])      # SW6 resumes a queue
@settings(max_examples=300, deadline=None, derandomize=True)
def test_the_frames_a_link_tells_are_let_through_whatever_the_answers_before_them(
        before, told):
    """The link's own bodies told ahead (the known state's, Link.tell) are judged as raw
    frames are: a prefix, each let through by the guard when it is sent after any
    answers to those before it; after a position read only frames that set nothing
    moving are told."""
    g = guard()
    for body, text in before:
        with contextlib.suppress(SafetyStop):
            sent(g, body, text)
    bodies_told = g.told_ahead([body for body, _ in told], 0)
    admitted = told[:len(bodies_told)]
    assert [body for body, _ in admitted] == bodies_told
    read = False
    for body, text in admitted:
        if read:
            assert Body.parse(body).name in MOVE_NOTHING
            continue                       # whatever the guard thinks then: nothing moves
        g.check(body)                      # SafetyStop if the guard refuses it now
        read = not sent(g, body, text) or Body.parse(body).name in POSITION_READS


class _TellingPort:
    """A port that takes frames told ahead and keeps what it was told."""

    def __init__(self) -> None:
        self.told: list[list[bytes]] = []

    def expect(self, frames) -> int:
        self.tell(frames)
        return len(frames)

    def tell(self, frames) -> bool:
        self.told.append([data for data, *_ in frames])
        return True


@pytest.mark.parametrize("own", [False, True])
def test_a_signal_after_the_frames_were_judged_keeps_them_untold(own):
    """Frames told a co-simulator run at once: a signal that lands once they were judged
    and before they are told keeps them all off its line (each is then barred at its own
    write); a signal answered by `H` bars the session's own frames no more."""
    g = guard()
    port = _TellingPort()
    ln = Link(port, g)
    with g.own_frames() if own else contextlib.nullcontext():
        ahead = Ahead(ln)
        assert all(ahead.admit(frame(body, 0, False), 0.25) for body in ("SR6", "SR0"))
        g.interrupts.signal()                         # Ctrl-C, no `H` sent yet
        assert not ahead.launch() and port.told == []
        ln.tell_port(ahead.frames, read=True)
        assert port.told == []
        g.interrupts.handle()                         # the session sent `H` and `D`
        assert ahead.launch() is own
        assert port.told == ([[frame("SR6", 0, False), frame("SR0", 0, False)]] if own
                             else [])
