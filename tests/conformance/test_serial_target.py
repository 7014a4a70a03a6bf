"""Done-when of the suite: a run against `python -m emulator --pty` through `serial:`
gives the same verdicts as the in-process run, apart from the cases that need the
emulator's test rig (which a serial port does not have)."""

from __future__ import annotations

import subprocess
import sys

import pytest

from conformance.case import select
from conformance.runner import run
from conformance.targets import parse_target
from conformance.verdict import COULD_NOT_TEST

pytestmark = pytest.mark.pty


def test_serial_run_matches_the_in_process_run():
    proc = subprocess.Popen([sys.executable, "-m", "emulator", "--model", "GVE84-100", "--pty"],
                            stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                            stderr=subprocess.DEVNULL, text=True)
    try:
        path = proc.stdout.readline().strip()
        cases = select()
        serial_target = parse_target(f"serial:{path}?baud=115200", profile="GVE84-100",
                                     allow_destructive=True, max_travel=100_000)
        over_pty = {r.id: r.verdict for r in run([serial_target], cases).results}
        in_process = {r.id: r.verdict for r in run([parse_target("emu:GVE84-100")],
                                                   cases).results}
    finally:
        proc.terminate()
        proc.wait(10)
    rig = {c.id for c in cases if c.rig}
    differ = {i: (in_process[i], over_pty[i]) for i in in_process
              if in_process[i] != over_pty[i] and not (i in rig and over_pty[i] == COULD_NOT_TEST)}
    assert differ == {}
