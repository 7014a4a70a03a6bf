"""Done-when of the suite: a run against `python -m emulator --pty` through `serial:`
gives the same verdicts as the in-process run, apart from the cases that need the
emulator's test rig (which a serial port does not have).

The directed and golden cases run here in real time, those with long moves in the slow
set; the Hypothesis machines, whose real-time runs take minutes, are compared with the
`hardware` settings by the slow test."""

from __future__ import annotations

import subprocess
import sys

import pytest

from conformance.run.runner import run
from conformance.run.selection import select
from conformance.targets import parse_target
from conformance.verdicts.verdict import COULD_NOT_TEST

pytestmark = pytest.mark.pty


def _compare(globs: list[str] | None, exclude: list[str] | None, settings_name: str) -> dict:
    proc = subprocess.Popen([sys.executable, "-m", "emulator", "--model", "GVE84-100", "--pty"],
                            stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                            stderr=subprocess.DEVNULL, text=True)
    try:
        path = proc.stdout.readline().strip()
        cases = select(globs, exclude)
        serial_target = parse_target(f"serial:{path}?baud=115200", profile="GVE84-100",
                                     allow_destructive=True, max_travel=100_000)
        pty_results = run([serial_target], cases, settings_name=settings_name).results
        over_pty = {r.id: r.verdict for r in pty_results}
        # frames the guard does not send to a real unit (beyond the envelope): by design
        guarded = {r.id for r in pty_results if any(n.startswith("safety stop")
                                                    for n in r.notes)}
        in_process = {r.id: r.verdict for r in run([parse_target("emu:GVE84-100")], cases,
                                                   settings_name=settings_name).results}
    finally:
        proc.terminate()
        proc.wait(10)
    rig = {c.id for c in cases if c.rig or c.hands} | guarded  # hands: nobody at the pty
    return {i: (in_process[i], over_pty[i]) for i in in_process
            if in_process[i] != over_pty[i] and not (i in rig and over_pty[i] == COULD_NOT_TEST)}


#: the long real-time moves (and the way back after each) are left to the slow test
LONG_MOVES = ["*machine*", "10.1.*", "10.2.*", "10.4.*", "10.5.*", "11.golden.g4c*",
              "11.golden.g6*", "5.errors.busy", "5.errors.n-while-run"]


def test_serial_run_matches_the_in_process_run():
    assert _compare(None, [*LONG_MOVES, "*measured*"], "ci") == {}


@pytest.mark.slow
def test_long_moves_over_serial_match_the_in_process_run():
    assert _compare(LONG_MOVES[1:], ["*measured*"], "ci") == {}


@pytest.mark.slow
def test_machines_over_serial_match_with_hardware_settings():
    assert _compare(["*machine*"], None, "hardware") == {}
