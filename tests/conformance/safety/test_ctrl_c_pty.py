"""Ctrl-C for real (issue 8 item 4): `gve-conformance` runs against the emulator on a pty
behind a proxy, which delivers SIGINT to it while a chosen frame is in flight. The next
frames on the line are H, then D; no motion follows; the EEPROM image (random bytes) and
the status words are as found; the reports are written and show the interrupted case."""

from __future__ import annotations

import json
import os
import random
import re
import signal
import subprocess
import sys
from collections.abc import Callable

import pytest

from tests.conformance.safety.proxy import unit_behind_proxy

pytestmark = pytest.mark.pty

#: frames that can start motion (the session's R after Ctrl-C follows its K of an empty
#: queue: it restores nothing, and the physical check below would see it if it did)
MOTION = re.compile(rb"!\d(L|C|G|W|\*E|SW6)")
ANSWERED = re.compile(rb"!0(?!\*S|C|B)")
CASES = ["--cases", "5.errors.ok", "--cases", "10.6.*", "--cases", "7.machine.packets",
         "--cases", "10.machine.queue-status-eeprom", "--cases", "8.index.*"]


def counting(pattern: bytes, n: int) -> Callable[[int, bytes], bool]:
    """The n-th frame that matches ``pattern``. Only frames the unit answers: the suite
    does not wait after `*S` or a packet member, so the signal would land in the frame
    after it."""
    seen = []
    return lambda i, frame: bool(re.match(pattern, frame)) and len(seen.append(i) or seen) == n


def in_machine(n: int) -> Callable[[int, bytes], bool]:
    """The n-th answered frame after the packet machine's first `*S`."""
    started, seen = [], []

    def trigger(i: int, frame: bytes) -> bool:
        if frame.startswith(b"!0*S"):
            started.append(i)
        return bool(started) and ANSWERED.match(frame) is not None and \
            len(seen.append(i) or seen) == n
    return trigger


def ctrl_c_run(tmp_path, trigger: Callable[[int, bytes], bool]) -> tuple[list[bytes], int, dict]:
    image = tmp_path / "unit.eeprom"
    data = bytearray(random.Random(str(tmp_path)).randbytes(256))
    image.write_bytes(bytes(data))
    pressed: list[int] = []
    proc: list[subprocess.Popen] = []
    stopped: list[list[int]] = []      # where the axes are once H has been answered

    def on_frame(i: int, frame: bytes) -> None:
        if proc and not pressed and trigger(i, frame):
            pressed.append(i)
            os.kill(proc[0].pid, signal.SIGINT)
        elif pressed and i == pressed[0] + 2:
            stopped.append(emu.state()["physical"])

    with unit_behind_proxy("--model", "GVE84-100", "--eeprom", str(image),
                           on_frame=on_frame) as (emu, proxy):
        emu.control("in 1 FF")
        proc.append(subprocess.Popen(
            [sys.executable, "-m", "conformance", "--target", f"serial:{proxy.path}",
             "--profile", "GVE84-100", "--allow-destructive", "--max-travel", "500", "--yes",
             "--report-dir", str(tmp_path / "reports"), *CASES],
            stdout=subprocess.PIPE, stderr=subprocess.PIPE))
        out, err = proc[0].communicate(timeout=120)
        state = emu.state()
    assert pressed, f"the trigger never fired\n{out.decode()}\n{err.decode()}"
    assert b"Traceback" not in err, err.decode()
    frames = proxy.sent()
    after = frames[pressed[0] + 1:]
    assert [f[2:3] for f in after[:2]] == [b"H", b"D"], after[:4]
    assert not [f for f in after if MOTION.match(f) and not f.startswith(b"!0L0,0,0")]
    assert state["physical"] == stopped[0], "the axes moved after H"
    assert image.read_bytes() == bytes(data), "EEPROM not as found"
    assert state["status"][:6] == ["00"] * 6
    (folder,) = (tmp_path / "reports").iterdir()
    report = json.loads((folder / "results.json").read_text())
    assert report["interrupted"] is True and proc[0].returncode == 1
    return after, pressed[0], report


def test_ctrl_c_inside_a_hypothesis_machine(tmp_path):
    _, _, report = ctrl_c_run(tmp_path, in_machine(3))
    assert report["results"][-1]["interrupted"] is True
    assert report["results"][-1]["id"] == "7.machine.packets"


def test_ctrl_c_while_a_case_writes_eeprom(tmp_path):
    _, _, report = ctrl_c_run(tmp_path, counting(rb"!0EW", 1))
    assert report["results"][-1]["interrupted"] is True


@pytest.mark.slow
@pytest.mark.parametrize("instant", range(12))
def test_ctrl_c_at_random_instants(tmp_path, instant):
    rnd = random.Random(instant)
    trigger = [counting(ANSWERED.pattern, rnd.randrange(1, 600)),  # anywhere
               counting(rb"!0ER", rnd.randrange(1, 256)),         # the EEPROM backup
               counting(rb"!0EW", rnd.randrange(1, 4)),           # a case writing EEPROM
               in_machine(rnd.randrange(1, 8))][instant % 4]        # inside a machine
    after, _, report = ctrl_c_run(tmp_path, trigger)   # (the whole protocol checked there)
    assert after[0][2:3] == b"H" and report["interrupted"] is True
