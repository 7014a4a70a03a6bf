"""What a replay prints of what it compared, and the one verdict that follows: two answers
whose bytes differ but were judged alike say why; a step not replayed is never an
agreement."""

from __future__ import annotations

from conformance.diff.engine import Disagreement, ExampleRun, StepRecord
from conformance.diff.replayed import frame_lines, header, verdict
from conformance.diff.sides import RoundTrip
from conformance.diff.steps import FRAME, INPUT, Step
from conformance.link.framing import parse_response

P = Step(FRAME, "P")


def _exchange(answer: bytes) -> RoundTrip:
    return RoundTrip(b"!0P\r", answer, 0, 1000, parse_response(answer, summed=False))


def _record(target: bytes, reference: bytes, alike: str = "", place: int = 0) -> StepRecord:
    return StepRecord(P, _exchange(target), _exchange(reference), alike=alike, place=place)


def test_answers_alike_within_the_band_say_so_on_their_line():
    out = ExampleRun([_record(b"0,35,0,0\r", b"0,3,0,0\r", alike="within ±40 step(s), read "
                           "while the axes may have moved"),
                   _record(b"0,80,0,0\r", b"0,80,0,0\r", place=1)], frames=2)
    first, second = frame_lines(out, [P, P], [b"0,35,0,0\r", b"0,80,0,0\r"])
    assert "target 0,35,0,0\\r" in first and "reference 0,3,0,0\\r" in first
    assert first.endswith("alike: within ±40 step(s), read while the axes may have moved")
    assert second.endswith(" same") and "recorded 0,80,0,0\\r" in second
    assert verdict(out, [P, P], {}).line == \
        "PASS: the target answers as the reference does (2 frames)"


def test_the_disagreeing_frame_is_marked_and_the_verdict_names_its_rule():
    rec = _record(b"0,35,0,0\r", b"0,3,0,0\r")
    d = Disagreement(0, "P", "position", rec.target, rec.reference, frozenset(),
                     frozenset(), rule="10.2.motion.positions-now", verdict="FAIL", tag="M")
    out = ExampleRun([rec], d, frames=1)
    line, rest = frame_lines(out, [P, Step(FRAME, "H")], [b""])
    assert line.endswith("DIFFERENT (position)") and "recorded -" in line
    assert rest == "  ... 1 step(s) not sent: a replay stops at its first disagreement"
    still = verdict(out, [P], {"rules": "10.2.motion.positions-now"})
    assert (still.word, still.status) == ("FAIL", 1)
    assert still.line == ("FAIL 10.2.motion.positions-now: !0P\\r target 0,35,0,0\\r, "
                          "reference 0,3,0,0\\r (position): still there")
    other = verdict(out, [P], {"rules": "3.frame.upper-case"})
    assert other.line.endswith("a disagreement other than the recorded 3.frame.upper-case")


def test_what_was_not_replayed_is_could_not_test_not_an_agreement():
    refused = ExampleRun([_record(b"0\r", b"0\r")], frames=1,
                      refused=["!0L5000,0,0\\r: beyond the envelope"])
    move = Step(FRAME, "L5000,0,0")
    assert frame_lines(refused, [P, move], [b"0\r", b"0\r"])[1] == \
        "  not sent (the guard): !0L5000,0,0\\r: beyond the envelope"
    v = verdict(refused, [P, move], {})
    assert (v.word, v.status) == ("COULD-NOT-TEST", 1)
    assert v.line.startswith("COULD-NOT-TEST: 1 step(s) not sent (the guard)")
    no_rig = verdict(ExampleRun([_record(b"0\r", b"0\r", place=1)], frames=1),
                     [Step(INPUT, port=0, value=0xFE), P], {})
    assert no_rig.line.startswith("COULD-NOT-TEST: 1 input step(s) not replayed")


def test_the_header_names_both_sides_and_what_was_recorded():
    lines = header("t.gvt", "tcp:h:1", "emu:GVE84-100", "GVE84-100",
                   {"rules": "3.frame.upper-case", "verdict": "FAIL",
                    "target-answer": "0,25020304\\r", "reference-answer": "3\\r"})
    assert lines[0] == "replay t.gvt: target tcp:h:1 against reference emu:GVE84-100 (GVE84-100)"
    assert lines[1] == ("recorded: FAIL 3.frame.upper-case: target 0,25020304\\r, "
                        "reference 3\\r")
