"""diff against somebody else's unit in virtual time grades a difference that another
profile of the same motion explains (a tick of its own, the dwell T placed elsewhere, A
along the path under VK) by the motion's own [D] rule, and one beyond every such profile
by the rule it touches: a third party's reading of the ramp is NON-STRICT, the same reading
graded exactly (--strict) FAILs, and a unit that ignores V FAILs through it all the same."""

from __future__ import annotations

import shlex
import sys
from pathlib import Path

from conformance.diff.course import Course
from conformance.diff.engine import Pair
from conformance.diff.labels import command_of, label
from conformance.diff.sides import RoundTrip, Side
from conformance.diff.steps import FRAME, WAIT, Step
from conformance.link.framing import parse_response
from conformance.motion.tolerance import TICK_NS, profile_reach
from conformance.targets import parse_target
from conformance.verdicts.verdict import FAIL, NON_STRICT
from gve_fixtures.profile import load_profile

CORPUS = Path(__file__).resolve().parents[3] / "corpus"
#: a simulator written from M84 alone that starts each motion on a 1 ms tick of its own
#: and accelerates along the path under VK
TICKED = "exec:" + shlex.join([sys.executable, str(CORPUS / "gve84-a" / "sim.py"), "--cosim",
                               "--model", "GVE84-100"])
EMULATOR = [sys.executable, "-m", "emulator", "--model", "GVE84-100", "--cosim"]


def _run(spec: str, steps: list[Step], *, strict: bool = False, profile: str = "GVE84-100"):
    target = parse_target(spec, profile=profile, allow_destructive=True, strict=strict)
    target.preflight()
    try:
        pair = Pair(Side(target, target.begin()), Side(parse_target(f"emu:{profile}")),
                    target.profile)
        return pair.run(steps).disagreement
    finally:
        target.session.finish()
        target.close()


def _frames(*bodies: str, wait: float) -> list[Step]:
    return [*(Step(FRAME, body=b) for b in bodies), Step(WAIT, seconds=wait),
            Step(FRAME, body="PF")]


def test_a_ramp_along_the_path_read_while_moving_is_the_profile_s_reading():
    d = _run(TICKED, _frames("VK", "L300,300,0", wait=0.4))
    assert d is not None and d.kind == "position"
    assert "profile" in d.context
    assert (d.rule, d.verdict) == ("10.2.motion.trapezoid", NON_STRICT)


def test_the_same_reading_graded_exactly_fails():
    d = _run(TICKED, _frames("VK", "L300,300,0", wait=0.4), strict=True)
    assert d is not None and d.kind == "position"
    assert "profile" not in d.context and d.verdict == FAIL


def test_where_the_motion_ends_at_rest_is_exact_for_every_reading():
    # long after the vector's end both read its target: the tick's reading differs in
    # nothing there
    assert _run(TICKED, _frames("VK", "L300,300,0", wait=2.0)) is None


def test_a_path_speed_ignored_is_ahead_of_every_profile():
    ignores_vk = "exec:" + shlex.join([*EMULATOR, "--mutant", "path-speed-ignored"])
    d = _run(ignores_vk, _frames("VK", "L300,300,0", wait=0.4))
    assert d is not None and d.kind == "position" and "profile" not in d.context
    assert (d.rule, d.verdict) == ("10.2.motion.path-rate", FAIL)


def test_a_rate_no_reading_allows_fails_through_another_profile():
    ignores_v = "exec:" + shlex.join([*EMULATOR, "--mutant", "velocity-ignored"])
    d = _run(ignores_v, _frames("V200", "L300,0,0", wait=1.0))
    assert d is not None and d.kind == "position"
    assert "profile" not in d.context
    assert d.verdict == FAIL and d.tag in ("M", "M-ex")


def test_the_reach_is_a_tick_an_event_and_the_dwell_a_reader_may_choose():
    ahead, behind = profile_reach(starts=1, changes=1, sooner_ns=4_000_000,
                                  later_ns=24_000_000, ramp_ns=0)
    assert ahead == 3 * TICK_NS + 4_000_000
    assert behind == 3 * TICK_NS + 24_000_000
    # under VK a whole ramp later each start (A along the path is the slower reading),
    # and a W's ramps later too: none sooner
    ahead_vk, behind_vk = profile_reach(starts=2, changes=0, sooner_ns=0,
                                        later_ns=5_000_000, ramp_ns=50_000_000,
                                        run_ramps_ns=7_000_000)
    assert (ahead_vk, behind_vk) == (3 * TICK_NS, 3 * TICK_NS + 2 * 55_000_000 + 7_000_000)


def test_a_dwell_given_by_t_is_nobody_s_choice_to_shorten():
    course = Course(load_profile("GVE84-100"))
    sooner, later = course.dwell_reach          # T after reset: a reader's 1..24 ms
    assert sooner > 0 and later == course.longest_t_ns
    course.took("T", "T12", RoundTrip(b"", b"0\r", 0, 0, parse_response(b"0\r", summed=False)))
    assert course.dwell_reach == (0, 12_000_000)


def test_a_start_that_skips_a_given_dwell_fails_through_another_profile():
    skips = "exec:" + shlex.join([*EMULATOR, "--mutant", "dwell-ignored"])
    steps = [Step(FRAME, body="T24"), Step(FRAME, body="A10000"), Step(FRAME, body="L2,0,0"),
             Step(WAIT, seconds=0.005), *_frames("L300,0,0", wait=0.006)]
    d = _run(skips, steps)
    assert d is not None and d.kind == "position" and "profile" not in d.context
    assert d.verdict == FAIL and d.rule == "10.2.motion.dwell"


def test_a_w_refused_as_a_syntax_error_is_the_reading_of_its_fields():
    # the reference took it, or ran it and found no switch (5): a reader of the other
    # form refuses it before its values (10.cmd.reference-syntax [D])
    syntax = "10.cmd.reference-syntax"
    assert label("W", "code", set(), set(), 0, 4) == syntax
    assert label("W", "code", {"after-run"}, set(), 5, 4) == syntax
    # refused at once for a value out of range: 4 there is the range's code missed
    assert label("W", "code", set(), set(), 5, 4) == "5.code.range"


def test_a_w_run_ramped_to_its_speeds_answers_within_its_own_ramps():
    # a simulator written from M84 alone that ramps its W run at A to n3 (the reference
    # runs at n3): no switch within 100 steps, answered 5 a ramp later
    ramped = "exec:" + shlex.join([sys.executable, str(CORPUS / "gve84-b" / "sim.py"),
                                   "--cosim", "--model", "GVE84-100"])
    d = _run(ramped, [Step(FRAME, body="WX,-100,1000,50,1000")])
    assert d is not None and d.kind == "timing"
    assert (d.rule, d.verdict) == ("10.2.motion.trapezoid", NON_STRICT)
    assert _run(ramped, [Step(FRAME, body="WX,-100,1000,50,1000")], strict=True).verdict == FAIL


def _gve54(spec: str, steps: list[Step], *, strict: bool = False):
    return _run(spec, steps, strict=strict, profile="GVE54")


def test_a_held_remainder_run_in_a_mode_taken_after_the_halt_is_a_reading():
    # a GVE54 written from M54 alone runs a halted vector's remainder in the mode an M
    # took while it was held; the reference keeps the mode it was accepted in
    rescaled = "exec:" + shlex.join([sys.executable, str(CORPUS / "gve54-b" / "sim.py"),
                                     "--cosim"])
    steps = [Step(FRAME, body="C200,0,0"), Step(FRAME, body="H"), Step(FRAME, body="M4"),
             Step(FRAME, body="G"), Step(WAIT, seconds=1.0), Step(FRAME, body="PF")]
    d = _gve54(rescaled, steps)
    assert d is not None and "mode-over-held" in d.context
    assert (d.rule, d.verdict) == ("10.1.queue.captured", NON_STRICT)
    assert _gve54(rescaled, steps, strict=True).verdict == FAIL
    # with no vector held, the mode's unit is the mode's rule
    course = Course(load_profile("GVE54"))
    ok = RoundTrip(b"", b"0\r", 0, 0, parse_response(b"0\r", summed=False))
    for body in ("C200,0,0", "M4"):
        course.took(command_of(body), body, ok)
    assert not course.mode_over_held
    for body in ("H", "M2"):
        course.took(command_of(body), body, ok)
    assert course.mode_over_held


def _in_process(spec: str, *, strict: bool = False, wait: float = 0.5):
    target = parse_target(spec, strict=strict)
    pair = Pair(Side(target), Side(parse_target("emu:GVE84-100")), target.profile)
    return pair.run([Step(FRAME, body="V20000"),
                     *_frames("L30000,0,0", wait=wait)]).disagreement


def test_counters_on_a_tick_of_their_own_are_the_profile_s_reading():
    # the reading counters-a-tick-late: 10 steps behind at 10 000 pulses/s
    late = "emu:GVE84-100?reading=counters-a-tick-late"
    d = _in_process(late)
    assert d is not None and "profile" in d.context
    assert (d.rule, d.verdict) == ("10.2.motion.trapezoid", NON_STRICT)
    assert _in_process(late, strict=True).verdict == FAIL
    # at rest it reads where the reference does
    assert _in_process(late, wait=4.0) is None
    d = _in_process(late + "&mutant=velocity-ignored")
    assert (d.rule, d.verdict) == ("10.2.motion.dominant-rate", FAIL)
