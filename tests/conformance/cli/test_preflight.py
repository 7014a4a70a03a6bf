"""The question before moving, asked once for several targets (a fleet's members have no
terminal): only an explicit yes moves; the emulator needs no question."""

from __future__ import annotations

import io

from conformance.cli.preflight import confirmed
from conformance.operator.console import Console
from conformance.run.metadata import RunMeta
from conformance.targets import parse_target


def _console(answer: str) -> tuple[Console, io.StringIO]:
    out = io.StringIO()
    return Console(io.StringIO(answer), out, interactive=True), out


def test_several_units_are_asked_about_once():
    targets = [parse_target(f"serial:/dev/ttyUSB{i}", profile="GVE84-100",
                            max_travel=500) for i in (0, 1)]
    meta = RunMeta()
    meta.target("serial:/dev/ttyUSB0").version = "IP84 v3 27.1.2010"
    console, out = _console("y\n")
    assert confirmed(targets, meta, console)
    shown = out.getvalue()
    assert shown.count("Move this machine? [y/N]") == 1
    assert "serial:/dev/ttyUSB0: IP84 v3 27.1.2010" in shown
    assert "serial:/dev/ttyUSB1: (no answer to ?)" in shown and "X ±500" in shown
    for answer in ("n\n", "\n", "", "yess\n"):
        assert not confirmed(targets, meta, _console(answer)[0])


def test_the_emulator_is_not_asked_about():
    console, out = _console("")
    assert confirmed([parse_target("emu:GVE54")], RunMeta(), console)
    assert out.getvalue() == ""
