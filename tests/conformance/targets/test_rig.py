"""The rig over docs/rig.md's control channel: against the emulator as a program (the
reference implementation of the channel), and against small simulators that answer
badly, late or not at all."""

from __future__ import annotations

import json
import sys

import pytest

from conformance.case.context import CouldNotTest
from conformance.link.liveness import TargetNotResponding
from conformance.targets import rig as rig_module
from conformance.targets.program import Program
from conformance.targets.rig import ControlRig

EMULATOR = [sys.executable, "-m", "emulator", "--pty"]


def simulator(replies: dict[str, str]) -> list[str]:
    """A program that prints a port, then answers each control line from ``replies``
    (a command without an entry gets no reply; `quit` ends it)."""
    return [sys.executable, "-c",
            "import json, sys\nreplies = json.loads(sys.argv[1])\nprint('/dev/null', "
            "flush=True)\nfor line in sys.stdin:\n    if line.strip() == 'quit':\n        break\n"
            "    reply = replies.get(line.strip())\n"
            "    if reply is not None:\n        print(reply, flush=True)",
            json.dumps(replies)]


@pytest.fixture
def started(monkeypatch):
    monkeypatch.setattr("conformance.targets.program.QUIT_SECONDS", 0.3)   # sleep: no quit
    programs: list[Program] = []

    def start(command: list[str]) -> Program:
        p = Program(command)
        programs.append(p)
        assert p.line(10) is not None          # its port
        return p

    yield start
    for p in programs:
        p.stop()


def test_the_emulator_s_channel_is_a_rig(started):
    restarts = []
    rig = ControlRig.detect(started(EMULATOR), 0, lambda: restarts.append(1))
    assert rig is not None and rig.found["profile"] == "GVE84-100"
    rig.set_input(1, 0xFE)
    rig.set_switch("X", -150)
    assert rig.state()["inputs"]["1"] == "FE"
    assert (rig.outputs(), rig.spindle()) == (0xFF, 0)
    rig.power_on()
    assert restarts == [1], "a power cycle is booked by whoever asked to hear of it"
    assert rig.state()["inputs"]["1"] == "FE", "inputs are levels: they outlive a restart"
    rig.hands_off()
    assert rig.state()["inputs"] == {"0": "FF", "1": "FF", "2": "FF"}


def test_several_units_answer_for_the_target_s_address(started):
    p = started([*EMULATOR, "--unit", "GVE84-100@0", "--unit", "GVE54@1"])
    rig = ControlRig.detect(p, 1)
    assert rig is not None and rig.found["profile"] == "GVE54"
    rig.set_input(1, 0xFE)
    assert rig.state()["profile"] == "GVE54" and rig.state()["inputs"]["1"] == "FE"
    p.send("state @0")
    assert json.loads(p.line(10) or "")["inputs"]["1"] == "FF", "the other unit untouched"


def test_a_program_that_does_not_read_its_input_has_no_rig(started):
    assert ControlRig.detect(started(["sh", "-c", "echo /dev/null; exec sleep 60"]), 0) is None


@pytest.mark.parametrize("answer", ["error: unknown control command 'state'", "ok",
                                    "[1, 2]", "{not json"])
def test_a_program_whose_state_is_not_an_object_has_no_rig(started, answer):
    assert ControlRig.detect(started(simulator({"state": answer})), 0) is None


def test_a_refused_command_makes_the_case_could_not_test(started):
    rig = ControlRig.detect(started(EMULATOR), 0)
    assert rig is not None
    with pytest.raises(CouldNotTest, match=r"the rig refused 'in 5 00': \"error: "):
        rig.set_input(5, 0x00)


def test_a_rig_that_stops_answering_makes_the_case_could_not_test(started, monkeypatch):
    monkeypatch.setattr(rig_module, "REPLY_SECONDS", 0.2)
    rig = ControlRig.detect(started(simulator({"state": "{}"})), 0)
    assert rig is not None
    with pytest.raises(CouldNotTest, match=r"the rig did not answer 'in 1 FE' within 0\.2 s"):
        rig.set_input(1, 0xFE)


def test_a_state_without_what_a_case_reads_makes_the_case_could_not_test(started):
    rig = ControlRig.detect(started(simulator({"state": '{"outputs": "zz"}'})), 0)
    assert rig is not None
    with pytest.raises(CouldNotTest, match="no readable 'outputs': \"zz\""):
        rig.outputs()
    with pytest.raises(CouldNotTest, match="no readable 'spindle': \"None\""):
        rig.spindle()


def test_a_reply_that_is_not_ok_makes_the_case_could_not_test(started):
    rig = ControlRig.detect(started(simulator({"state": "{}", "power-on": "done"})), 0)
    assert rig is not None
    with pytest.raises(CouldNotTest, match="answered 'power-on' with \"done\", not ok"):
        rig.power_on()


def test_a_program_that_ended_makes_the_target_not_responding(started):
    p = started(EMULATOR)
    rig = ControlRig.detect(p, 0)
    assert rig is not None
    p.process.kill()
    p.wait(10)
    with pytest.raises(TargetNotResponding, match="was killed by signal 9"):
        rig.set_input(1, 0xFE)
