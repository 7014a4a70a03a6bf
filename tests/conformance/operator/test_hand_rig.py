"""The technician as the test rig: an emulated unit on a pty judged as a real unit (no
rig), a scripted operator whose hands are the emulator's control channel. Every rig case
a hand can do runs to PASS; a skipped step is COULD-NOT-TEST "skipped by the operator";
the rig cases no hand can do say why; no motion while a step is open."""

from __future__ import annotations

import contextlib
import io
import json

import pytest

import conformance.cases  # noqa: F401  (registers the cases)
from conformance.case.context import REGISTRY, Case
from conformance.link.framing import parse_response
from conformance.link.safety import Guard
from conformance.link.stops import SafetyStop
from conformance.link.virtual import Rig
from conformance.operator.console import Console, HandStep
from conformance.operator.hands import HandRig, cannot_by_hand, wording
from conformance.run.runner import CaseResult, run
from conformance.targets import parse_target
from conformance.targets.rig import ControlRig
from conformance.verdicts.verdict import COULD_NOT_TEST, PASS, CouldNotTest
from gve_fixtures.profile import load_profile
from tests.conformance.operator.terminal import EmulatedUnit

pytestmark = pytest.mark.pty

PROFILE = "GVE84-100"
#: one profile of each family, for the hand cases' PASS
FAMILIES = ("GVE54", "GVE84-100", "GVE114-200")


class ScriptedOperator(Console):
    """A technician who does every step asked with the emulator's control channel (the
    person's hands) and reads the outputs off its state (the person's eyes); the kinds
    in ``skip`` are skipped."""

    def __init__(self, unit: EmulatedUnit, skip: tuple[str, ...] = ()) -> None:
        super().__init__(stdin=io.StringIO(), stdout=io.StringIO(), interactive=True)
        self.unit, self.skip = unit, skip
        self.asked: list[HandStep] = []

    def hand_step(self, step: HandStep) -> bool:
        self.asked.append(step)
        if step.kind in self.skip:
            return False
        if step.kind == "input":
            assert self.unit.rig(f"in {step.port} {step.level:02X}").strip() == "ok"
        elif step.kind == "power-on":
            assert self.unit.rig("power-on").strip() == "ok"
        return True

    def observe(self, step: HandStep) -> str | None:
        self.asked.append(step)
        if step.kind in self.skip:
            return "s"
        outputs = int(json.loads(self.unit.rig("state"))["outputs"], 16)
        return " ".join(str(n) for n in range(8) if not outputs >> n & 1) or "none"


def _rig_cases(by_hand: bool, name: str = PROFILE) -> list[Case]:
    profile = load_profile(name)
    return [c for id, c in sorted(REGISTRY.items()) if c.rig and c.missing_for(profile) is None
            and (cannot_by_hand(id) is None) == by_hand]


def _by_hand_everywhere() -> list:
    """Every hand case on every family: in the default run each case on one family, the
    families taken in turn (so every family and every case is there), the rest slow (a
    case that restarts the unit waits out the restart in real time)."""
    every = sorted({c.id for name in FAMILIES for c in _rig_cases(True, name)})
    params = []
    for name in FAMILIES:
        for c in _rig_cases(True, name):
            k = every.index(c.id)
            having = [f for f in FAMILIES if c in _rig_cases(True, f)]
            default = having[k % len(having)]
            params.append(pytest.param(name, c, marks=() if name == default
                                       else pytest.mark.slow))
    return params


@pytest.fixture
def unit(request):
    u = EmulatedUnit(getattr(request, "param", PROFILE))
    yield u
    u.close()


def _run(unit: EmulatedUnit, case: Case, operator: Console | None) -> CaseResult:
    target = parse_target(f"serial:{unit.path}", profile=unit.model, allow_destructive=True)
    result = run([target], [case], console=operator)
    assert result.problems == []
    (only,) = result.results
    return only


def test_the_hand_cases_cover_inputs_the_power_and_the_outputs():
    ids = {c.id for c in _rig_cases(by_hand=True)}
    # one of each kind of hand step (a set drawn from the registry, not a list of all)
    assert {"10.cmd.reference.inputs", "10.6.eeprom.kept-across-restarts",
            "10.cmd.output.port"} <= ids
    assert not ids & set(wording()["cannot"])


@pytest.mark.parametrize(("unit", "case"), _by_hand_everywhere(), indirect=["unit"],
                         ids=lambda x: getattr(x, "id", x))
def test_every_rig_case_a_hand_can_do_passes_by_hand(unit, case):
    operator = ScriptedOperator(unit)
    r = _run(unit, case, operator)
    assert r.verdict == PASS, (r.notes, [c for c in r.checks if not c["ok"]])
    assert operator.asked, "the technician was asked nothing"
    out = operator.stdout.getvalue()
    steps = [s for s in operator.asked if s.kind in ("input", "power-on")]
    assert out.count("verified:") >= len(steps)         # every step read back


@pytest.mark.parametrize("case", _rig_cases(by_hand=True), ids=lambda c: c.id)
def test_a_skipped_hand_step_is_could_not_test(unit, case):
    operator = ScriptedOperator(unit, skip=("input", "power-on", "outputs"))
    r = _run(unit, case, operator)
    assert r.verdict == COULD_NOT_TEST
    assert any("skipped by the operator" in n for n in r.notes), r.notes


def test_without_an_operator_the_hand_cases_say_how_to_run_them(unit):
    r = _run(unit, REGISTRY["10.cmd.output.port"], None)
    assert r.verdict == COULD_NOT_TEST
    assert "--operator" in r.notes[0] and "needs a test rig" in r.notes[0]


@pytest.mark.parametrize("case", _rig_cases(by_hand=False), ids=lambda c: c.id)
def test_a_rig_case_no_hand_can_do_says_why(unit, case):
    operator = ScriptedOperator(unit)
    r = _run(unit, case, operator)
    assert r.verdict == COULD_NOT_TEST and operator.asked == []
    assert r.notes == [f"needs a test rig: no hand can do it: {cannot_by_hand(case.id)}"]


def test_every_case_no_hand_can_do_is_a_rig_case():
    for id in wording()["cannot"]:
        assert id in REGISTRY and REGISTRY[id].rig, id


def test_a_step_done_wrong_is_asked_again_then_given_up(unit):
    class Wrong(ScriptedOperator):
        def hand_step(self, step: HandStep) -> bool:
            self.asked.append(step)
            assert self.unit.rig("in 1 F7").strip() == "ok"      # IN3, not the one asked
            return True
    operator = Wrong(unit)
    r = _run(unit, REGISTRY["10.cmd.reference.inputs"], operator)
    assert r.verdict == COULD_NOT_TEST
    grounding = [s for s in operator.asked if s.level == 0xFD]     # IN1 grounded
    assert len(grounding) == wording()["attempts"]
    assert "try again" in operator.stdout.getvalue()
    assert any("not verified, I1 reads F7" in n for n in r.notes), r.notes


def test_no_motion_while_a_hand_step_is_open():
    guard = Guard(load_profile(PROFILE), 0, max_travel=2000, allow_destructive=True)
    guard.check("L100,0,0")
    with guard.hands_on(), pytest.raises(SafetyStop, match="while a hand step is open"):
        guard.check("L100,0,0")
    guard.check("I1")                      # reading the unit back is not motion
    guard.check("L100,0,0")


def test_the_hands_and_the_control_channel_are_one_rig_interface():
    assert isinstance(HandRig(lambda: None, None), Rig)
    assert isinstance(ControlRig(lambda c: "ok", {"position": [0, 0, 0]}, 0), Rig)


def test_a_hand_case_whose_input_is_already_so_asks_nothing(unit):
    operator = ScriptedOperator(unit)
    r = _run(unit, REGISTRY["10.3.interrupt.polarity"], operator)   # IN0 reads 1 as found
    assert r.verdict == PASS and operator.asked == []


class _Unit:
    """A link to a unit whose SR6 reads ``st6`` and whose I1 reads ``inputs`` (a step
    done by the technician changes it): what HandRig sees of a link."""

    def __init__(self, st6: str, inputs: str = "FF") -> None:
        self.guard = Guard(load_profile(PROFILE), 0, max_travel=2000, allow_destructive=True)
        self.st6, self.inputs = st6, inputs

    def _answer(self, body: str):
        value = self.st6 if body == "SR6" else self.inputs
        return parse_response(f"0,{value}\r".encode(), summed=False)

    def send(self, body: str):
        return self._answer(body)

    def poll(self, body: str, until, max_seconds: float = 30.0):
        r = self._answer(body)
        return r if until(r) else None

    def spending(self, spent):
        return contextlib.nullcontext()


class _Hand(Console):
    """Grounds IN0 when asked, and tries to move the unit meanwhile."""

    def __init__(self, unit: _Unit) -> None:
        super().__init__(stdin=io.StringIO(), stdout=io.StringIO(), interactive=True)
        self.unit, self.asked, self.refused = unit, 0, ""

    def hand_step(self, step: HandStep) -> bool:
        self.asked += 1
        with pytest.raises(SafetyStop) as refused:
            self.unit.guard.check("L100,0,0")
        self.refused = str(refused.value)
        self.unit.inputs = "FE"
        return True


def test_no_step_is_asked_while_the_unit_moves():
    unit = _Unit(st6="40")                        # RUN = 1, INTA = 0: moving (spec 5)
    hand = _Hand(unit)
    with pytest.raises(CouldNotTest, match="did not come to rest"):
        HandRig(lambda: unit, hand).set_input(1, 0xFE)
    assert hand.asked == 0


def test_a_step_is_asked_with_halted_vectors_and_no_motion_meanwhile():
    unit = _Unit(st6="C0")                        # RUN held by INTA: at rest
    hand = _Hand(unit)
    HandRig(lambda: unit, hand).set_input(1, 0xFE)
    assert hand.asked == 1 and "while a hand step is open" in hand.refused
    unit.guard.check("L100,0,0")                  # the prompt answered: motion again


class _Eyes(Console):
    """Answers the outputs question with ``answers``, one after the other."""

    def __init__(self, *answers: str) -> None:
        super().__init__(stdin=io.StringIO(), stdout=io.StringIO(), interactive=True)
        self.answers = list(answers)

    def observe(self, step: HandStep) -> str | None:
        return self.answers.pop(0)


def test_the_outputs_are_read_as_the_technician_sees_them():
    unit = _Unit(st6="00")
    assert HandRig(lambda: unit, _Eyes("2")).outputs() == 0xFB          # OUT2 on: active low
    assert HandRig(lambda: unit, _Eyes("0, 7")).outputs() == 0x7E
    assert HandRig(lambda: unit, _Eyes("none")).outputs() == 0xFF
    eyes = _Eyes("lots", "9", "2 3")                                     # asked again
    assert HandRig(lambda: unit, eyes).outputs() == 0xF3
    assert eyes.stdout.getvalue().count("please answer") == 2
    with pytest.raises(CouldNotTest, match="reading the outputs: skipped by the operator"):
        HandRig(lambda: unit, _Eyes("s")).outputs()
    # nobody to ask: the step it needs is named, never an empty one
    with pytest.raises(CouldNotTest, match=r"needs a hand: read which outputs are on \(lit\); "
                                           "run on a terminal"):
        HandRig(lambda: unit, None).outputs()


def test_a_power_cycle_not_done_is_caught_by_the_index(unit):
    class NoPower(ScriptedOperator):
        def hand_step(self, step: HandStep) -> bool:
            if step.kind == "power-on":
                self.asked.append(step)
                return True                     # Enter, the power never cycled
            return super().hand_step(step)
    operator = NoPower(unit)
    r = _run(unit, REGISTRY["10.3.inputs.physical-across-restart"], operator)
    assert r.verdict == COULD_NOT_TEST
    assert [s.kind for s in operator.asked].count("power-on") == wording()["attempts"]
    assert any("not verified, the index reads" in n for n in r.notes), r.notes
    assert json.loads(unit.rig("state"))["inputs"]["1"] == "FF"      # the hands came off
