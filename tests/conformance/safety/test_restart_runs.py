"""Runs against a unit that restarts by itself (tests/conformance/safety/restarting_unit.py:
it loses a frame, is deaf 3.5 s and comes back with its counters at 0, its axes where they
stopped): during a move, between cases and during a Hypothesis example, with a test rig
that has eyes (a simulator's `physical`: the axes are located and the run goes on) and
without one (no motion after the restart). Whatever happens, no axis goes physically
beyond --max-travel, the run does not pass and the restart is named; the emulator's own
`physical` and `excursion` (docs/rig.md) tell where the axes really went.

In virtual time in process and through the CLI with a co-simulator; over a pty in real
time (the quiet-line waits and timeouts there are the real-time path's own)."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest

from conformance.cli import main
from conformance.link import bookkeeping
from conformance.run.runner import run
from conformance.run.selection import select
from conformance.verdicts.verdict import FAILED, overall
from emulator.readings import READINGS
from tests.conformance.safety.restarting_unit import arm, condition
from tests.conformance.safety.units import virtual_unit
from tests.emulator.process import Emulator

TRAVEL = 1500
#: where the restart falls: (frame pattern, n-th, an axis physically beyond, moving?,
#: the cases run)
PLACES = {
    # X on its way out beyond 1000 steps, as the tester saw it (~1360 of 1500)
    "during-a-move": ("SR6|PF|F|L|C|@", 1, "X:1000", True, ["10.1.*", "10.2.*", "10.4.*"]),
    # the known state's first frame (H) with X left out by the case before
    "between-cases": ("H", 1, "X:300", False, ["10.1.*", "10.4.*"]),
    # a frame of a stateful machine's example while X moves
    "during-an-example": (".", 12, "X:5", True, ["10.5.machine.keep-restore"]),
}


def _physically_within(state: dict) -> None:
    for axis, (lo, hi) in enumerate(state["excursion"]):
        assert lo >= -TRAVEL and hi <= TRAVEL, (axis, lo, hi)


def _named(result) -> str:
    """The restart as the run names it: the first problem, and a case's note."""
    assert result.problems, "the restart is not reported"
    first = result.problems[0]
    assert "restarted by itself" in first or "no longer tell where the axes are" in first
    notes = [n for r in result.results for n in r.notes if "safety stop: " + first[:60] in n]
    assert notes, "no case names it"
    return first


@pytest.mark.parametrize("place", sorted(PLACES))
@pytest.mark.parametrize("eyes", [True, False], ids=["rig-with-eyes", "no-rig"])
def test_a_restart_anywhere_stays_within_the_envelope_and_is_named(place, eyes, monkeypatch):
    pattern, nth, beyond, moving, globs = PLACES[place]
    unit = virtual_unit(max_travel=TRAVEL, rig=eyes)
    restarts = arm(unit.unit, pattern, nth, 3500, condition(beyond, moving))
    lost_at: list[list[int]] = []       # where the axes physically were once the guard knew
    read = bookkeeping.Bookkeeping._read

    def watched(guard, name, counters, **kw):
        read(guard, name, counters, **kw)
        if guard.lost and not lost_at:
            lost_at.append(unit.state()["physical"])
    monkeypatch.setattr(bookkeeping.Bookkeeping, "_read", watched)
    result = run([unit], select(globs))
    state = unit.state()
    assert len(restarts) == 1, "the restart never came"
    _physically_within(state)
    first = _named(result)
    assert overall(result.results, result.interrupted, result.problems)[0] == FAILED
    if eyes:
        # the rig's eyes located the axes: the run went on and put them back
        assert state["physical"] == [0, 0, 0]
        assert "no motion" not in first or "located them" in first
    elif lost_at:
        # nothing tells where they stopped: no motion frame went out after that
        assert state["physical"] == lost_at[0]
        assert "no motion frame went out after it" in first
        assert any(p.startswith("axes not brought back") for p in result.problems)
    else:
        # they stood still where they were known: counted on from there
        assert "the run went on from there" in first and state["physical"] == [0, 0, 0]


EVERY = tuple(sorted(READINGS))


@pytest.mark.parametrize(("profile", "readings"), [
    ("GVE114-500", ()),
    *(pytest.param(p, EVERY, marks=pytest.mark.slow) for p in ("GVE84-100", "GVE54",
                                                                  "GVE114-500"))])
def test_a_clean_unit_is_never_taken_for_restarted(profile, readings):
    """Every case, J and W included, on a clean unit and on one taking every other reading
    of the manuals' silences: no restart seen, nothing left unrestored."""
    unit = virtual_unit(profile, allow_destructive=True, readings=readings)
    result = run([unit], select(None))
    assert result.problems == [] and not unit.session.guard.restarts


def _cosim(tmp_path: Path, *options: str) -> tuple[int, str, dict, dict]:
    """The CLI against the restarting unit as a co-simulator; its exit status, output,
    results.json and the unit's state at the end."""
    state = tmp_path / "state.json"
    program = (f"{sys.executable} -m tests.conformance.safety.restarting_unit {' '.join(options)}"
               f" --state {state} -- --model GVE84-100 --cosim")
    status = main(["--target", f"exec:{program}", "--profile", "GVE84-100", "--yes",
                   "--max-travel", str(TRAVEL), "--cases", "10.1.*", "--cases", "10.2.*",
                   "--cases", "10.4.*", "--report-dir", str(tmp_path / "reports")])
    (folder,) = (tmp_path / "reports").iterdir()
    return status, folder, json.loads((folder / "results.json").read_text()), \
        json.loads(state.read_text())


@pytest.mark.parametrize("rig", [True, False], ids=["rig", "no-rig"])
def test_through_the_cli_the_restart_is_named_everywhere(tmp_path, capsys, rig):
    status, folder, results, state = _cosim(
        tmp_path, "--at", "'SR6|PF|F|L|C|@#1'", "--beyond", "X:1000", "--moving",
        *(() if rig else ("--no-rig",)))
    out = capsys.readouterr().out
    assert len(state["restarted"]) == 1
    _physically_within(state)
    assert status == 1
    last = out.strip().splitlines()[-1]
    assert last.startswith("FAILED — 1 problem(s)") or last.startswith("FAILED")
    assert "PROBLEM: the unit restarted by itself" in out
    problem = results["problems"][0]
    assert "restarted by itself" in problem
    assert ("located them" in problem) if rig else ("no motion frame went out" in problem)
    for report in ("report.html", "junit.xml"):
        assert "restarted by itself" in (folder / report).read_text()
    if rig:
        assert state["physical"] == [0, 0, 0]
        assert "restored: axes back where the run began" in out
    else:
        assert "PROBLEM: axes not brought back where the run began" in out
        assert "restored: axes" not in out


@pytest.mark.pty
def test_over_a_pty_the_restart_is_seen_and_no_axis_leaves_the_envelope(tmp_path, capsys):
    """Real time: the frame in flight is lost, its timeout and the quiet wait after it
    pass while the unit is deaf; a serial: target has no rig, so nothing moves after."""
    emu = _restarting_pty("--at", "SR6|PF|F|L|C|@#1", "--beyond", "X:1000", "--moving")
    try:
        status = main(["--target", f"serial:{emu.first}", "--profile", "GVE84-100", "--yes",
                       "--max-travel", str(TRAVEL), "--cases", "10.1.*", "--cases", "10.2.*",
                       "--report-dir", str(tmp_path)])
        state = emu.state()
        restarted = emu.control("restarted")
    finally:
        emu.stop()
    out = capsys.readouterr().out
    assert restarted == "1"
    _physically_within(state)
    assert status == 1 and "PROBLEM: the unit restarted by itself" in out
    assert "PROBLEM: axes not brought back where the run began" in out


def _restarting_pty(*options: str) -> Emulator:
    return Emulator(*options, "--", "--model", "GVE84-100", "--pty",
                    module="tests.conformance.safety.restarting_unit")
