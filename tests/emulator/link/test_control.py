"""The control channel in process: each line does what a rig's hands would, answers
``ok``/JSON, and anything it does not understand is an ``error: ...`` line, never a crash."""

from __future__ import annotations

import json

import pytest

from emulator.link.control import Quit, handle
from emulator.link.line import Line
from tests.emulator.link.fake_unit import FakeUnit


def test_commands_reach_the_unit() -> None:
    unit = FakeUnit()
    line = Line([unit], 9600)
    assert handle(line, "in 1 FE\n") == "ok"
    assert unit.inputs == {1: 0xFE}
    assert handle(line, "switch y -1500") == "ok"
    assert handle(line, "switch Y none") == "ok"
    assert unit.switches == {"Y": None}
    assert handle(line, "power-on") == "ok" and unit.powered == [0]
    assert json.loads(handle(line, "state")) == {"address": 0, "t": 0, "inputs": {"1": 254}}
    assert handle(line, "   ") is None


def test_the_rate_switch_is_read_at_power_on() -> None:
    unit = FakeUnit()
    line = Line([unit], 9600)
    assert handle(line, "rate 19200") == "ok" and unit.rate_switch == 19200
    assert unit.rate is None
    assert handle(line, "power-on") == "ok" and unit.rate == 19200
    assert handle(line, "rate none") == "ok" and unit.rate_switch is None
    assert handle(line, "rate fast").startswith("error: rate POS: POS takes digits")


def test_state_of_several_units_is_keyed_by_address() -> None:
    line = Line([FakeUnit(0), FakeUnit(4)], 9600)
    assert handle(line, "in 2 0F @4") == "ok"
    state = json.loads(handle(line, "state"))
    assert set(state) == {"0", "4"} and state["4"]["inputs"] == {"2": 15}


@pytest.mark.parametrize("text", ["fly 1", "in 1", "in 1 ZZ", "in 9 00", "in 1 100",
                                  "switch Y here", "state 3", "in 1 FE @7", "power-on now",
                                  "state @z", "@", "in \u00b2 00", "in 1 \u00b2F",
                                  "switch X \u00b2", "switch X " + "9" * 5000, "switch Q 5",
                                  "in 1 +F"])
def test_malformed_lines_answer_an_error(text: str) -> None:
    line = Line([FakeUnit()], 9600)
    answer = handle(line, text)
    assert answer is not None and answer.startswith("error: ")


@pytest.mark.parametrize("text", ["quit", "exit", "QUIT\n"])
def test_quit(text: str) -> None:
    with pytest.raises(Quit):
        handle(Line([FakeUnit()], 9600), text)
