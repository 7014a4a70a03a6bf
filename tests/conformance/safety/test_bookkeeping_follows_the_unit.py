"""The guard's bookkeeping of where the frames put the axes (conformance/link/envelope.py
through the guard) is a model of the unit too: whatever frames go out and however a unit
that keeps the manuals answers them (the emulator, taking any of the readings of their
silences), the place the bookkeeping gives each axis always holds where the axis
physically is, and the guard never takes such a unit for one that restarted or whose
counters disagree with the frames. The unit is the emulator in process in virtual time
judged as a real unit (its session's guard books every frame); its `state` tells where
the axes physically are (docs/rig.md)."""

from __future__ import annotations

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from conformance.link.body import Body
from conformance.link.liveness import TargetNotResponding
from conformance.link.stops import SafetyStop
from emulator.readings import READINGS
from gve_fixtures.profile import load_profile
from tests.conformance.safety.units import virtual_unit

#: the envelope: far enough that most sequences run whole, near enough to be met
TRAVEL = 1500
#: a step: a frame's body (with the lines its answer takes), or seconds to wait
WAITS = (0.001, 0.01, 0.05, 0.2, 0.6, 1.0, 2.5)


def _component() -> st.SearchStrategy[str]:
    number = st.one_of(st.sampled_from([0, 1, -1]), st.integers(-300, 300))
    # now and then a form a lenient reading takes otherwise (spec 3: 4 or a reading)
    odd = st.sampled_from(["", "+1", "1x", "-", "0000005", " 7"])
    return st.one_of(number.map(str), number.map(str), number.map(str), odd)


def _vector(command: str) -> st.SearchStrategy[str]:
    return st.lists(_component(), min_size=1, max_size=4).map(
        lambda parts: command + ",".join(parts))


#: frames besides vectors: settings, events, reads, restarts, packets, checksum mode,
#: reference runs (each drawn where the profile has its command)
OTHERS = ["V500", "V3000", "A5", "A50", "B200", "T1", "$10", "XU", "XD", "XA", "@", "SW6,80",
          "SW6,00", "SW0,01", "SW0,00", "SW2,01", "SW2,00", "l50,0,0", "H", "G", "D", "K",
          "R", "N", "SR6", "F", "PF", "P", "J", "*S", "*E1", "*E2", "VK", "VN", "XM50",
          "XM200", "%+", "%-", "NX7", "NY-3", "M2", "M4", "M8", "MF", "WX,200,1000,50,500",
          "WY,-150,1000,40,500"]


def _frames(profile: str) -> st.SearchStrategy[list[tuple[str, int] | float]]:
    commands = load_profile(profile).commands
    others = [body for body in OTHERS if Body.parse(body).name.rstrip("6") in commands]
    frame = st.one_of(_vector("L"), _vector("C"), _vector("C"), st.sampled_from(others),
                      st.sampled_from(others)).map(lambda body: [(body, 1)])
    wait = st.sampled_from(WAITS).map(lambda seconds: [seconds])
    # `>` answers in two lines (spec 8)
    steps = [frame, frame, wait, st.just([(">", 2)]), st.builds(_kept, _vector("C"), wait)]
    if "*S" in commands:
        steps.append(st.builds(_packet, st.lists(_vector("C"), min_size=1, max_size=3),
                               st.one_of(st.just([]), wait), st.integers(0, 4)))
    return st.lists(st.one_of(*steps), min_size=12, max_size=40).map(
        lambda parts: [step for part in parts for step in part])


def _packet(members: list[str], wait: list[float], count: int) -> list:
    """`*S`, its members, maybe a pause (a watchdog may drop the packet), `*E` (4: none)."""
    end = [(f"*E{count}", 1)] if count < 4 else []
    return [("*S", 1), *((m, 1) for m in members), *wait, *end]


def _kept(vector: str, wait: list[float]) -> list:
    """A vector kept part way: the read after K tells how far it got."""
    return [(vector, 1), *wait, ("H", 1), ("K", 1), ("PF", 1)]


#: readings of the manuals' silences a careful implementer may take (emulator/readings.py):
#: none, every one at once, or a few
_READINGS = st.one_of(st.just([]), st.just(sorted(READINGS)),
                      st.lists(st.sampled_from(sorted(READINGS)), max_size=6, unique=True))


def _run(profile: str, readings: list[str], steps: list) -> None:
    unit = virtual_unit(profile, max_travel=TRAVEL, allow_destructive=True, rig=False,
                        readings=tuple(readings))
    session = unit.begin()
    link = session.open_link()
    guard = session.guard
    origin = unit.state()["physical"]
    done: list[str] = []
    for step in steps:
        if isinstance(step, float):
            link.wait(step)
            done.append(f"wait {step}")
        else:
            body, lines = step
            try:
                r = link.send(body, lines=lines)
            except SafetyStop as stop:          # beyond the envelope: not sent
                assert not guard.lost, (str(stop), done)
                done.append(f"{body} not sent")
                continue
            except TargetNotResponding:
                # frames sent into a restart (J) one after the other, or a `>` with no
                # history answered in one line where two were awaited: the run would stop
                return
            done.append(f"{body} → {r.text if r is not None else 'no answer'}")
        here = unit.state()["physical"]
        reach = guard.envelope.reach()
        for axis, (p, span) in enumerate(zip(here, reach, strict=False)):
            assert span.lo <= p - origin[axis] <= span.hi, (
                f"axis {axis} is at {p - origin[axis]}, the bookkeeping says {span}", done)
        assert not guard.restarts and not guard.untracked and not guard.lost, (
            [str(e) for e in (*guard.restarts, *guard.untracked)], done)


@pytest.mark.parametrize("profile", ["GVE84-100", "GVE54", "GVE114-500"])
def test_the_bookkeeping_always_holds_where_the_axes_are(profile):
    @settings(max_examples=60, deadline=None, derandomize=True,
              suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
    @given(readings=_READINGS, steps=_frames(profile))
    def follows(readings, steps):
        _run(profile, readings, steps)

    follows()


def test_the_sequences_that_found_the_gaps_are_followed():
    """Found by the property above: a unit that commits packet members as they arrive; a
    B answered after a packet the unit dropped; a read after K that tells how far the
    queue got before the remainder is given back."""
    _run("GVE84-100", ["packet-committed-on-arrival"],
         [("*S", 1), ("C300,0,0", 1), 1.0, ("*S", 1), ("H", 1), ("SR6", 1), ("PF", 1)])
    _run("GVE84-100", ["packet-watchdog"],
         [("*S", 1), 1.0, ("B200", 1), ("L1,0,0", 1), ("L0,0,0", 1), ("PF", 1)])
    _run("GVE84-100", [],
         [("c40,0,0", 1), ("K", 1), ("PF", 1), ("H", 1), ("R", 1), ("G", 1), 1.0,
          ("F", 1), ("PF", 1)])
