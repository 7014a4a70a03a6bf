"""Ctrl-C for real: `gve-conformance` runs against the emulator on a pty
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
import threading
import time
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


#: the main suite's command line against the proxy's port and a report folder
SUITE = ["--target", "serial:{port}", "--profile", "GVE84-100", "--allow-destructive",
         "--max-travel", "500", "--yes", "--report-dir", "{reports}", *CASES]
#: diff's, searching long enough for any trigger to fire
DIFF = ["diff", "--target", "serial:{port}", "--profile", "GVE84-100", "--allow-destructive",
        "--max-travel", "500", "--yes", "--report-dir", "{reports}", "--seconds", "60"]


def ctrl_c_run(tmp_path, trigger: Callable[[int, bytes], bool], *, sig: int = signal.SIGINT,
               after_s: float = 0.0, drop: bool = False, command: list[str] = SUITE
               ) -> tuple[list[bytes], int, dict]:
    """The run, signalled ``after_s`` after the frame ``trigger`` picks (at once: while it
    is in flight). ``drop``: that frame's answer is lost, so the link waits for a quiet
    line before its next frame and the signal lands inside that wait."""
    image = tmp_path / "unit.eeprom"
    data = bytearray(random.Random(str(tmp_path)).randbytes(256))
    image.write_bytes(bytes(data))
    pressed: list[int] = []
    signalled: list[float] = []        # the instant of the signal (the proxy's clock)
    dropping: list[bool] = []
    proc: list[subprocess.Popen] = []
    stopped: list[list[int]] = []      # where the axes are once H has been answered

    def press() -> None:
        signalled.append(time.monotonic())
        os.kill(proc[0].pid, sig)

    def on_frame(i: int, frame: bytes) -> None:
        if proc and not pressed and trigger(i, frame):
            pressed.append(i)
            if drop:
                dropping.append(True)
            if after_s:
                threading.Timer(after_s, press).start()
            else:
                press()
        elif signalled and frame[2:3] == b"D" and not stopped:
            stopped.append(emu.state()["physical"])

    def lose_one(answer: bytes) -> list[tuple[float, bytes]]:
        if dropping:
            dropping.clear()
            return []
        return [(0.0, answer)]

    with unit_behind_proxy("--model", "GVE84-100", "--eeprom", str(image),
                           on_frame=on_frame, transform=lose_one) as (emu, proxy):
        emu.control("in 1 FF")
        argv = [a.format(port=proxy.path, reports=tmp_path / "reports") for a in command]
        proc.append(subprocess.Popen([sys.executable, "-m", "conformance", *argv],
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE))
        out, err = proc[0].communicate(timeout=120)
        state = emu.state()
    assert signalled, f"the trigger never fired\n{out.decode()}\n{err.decode()}"
    assert b"Traceback" not in err, err.decode()
    after = [f for t, f in proxy.frames if t > signalled[0]]
    # H first; when that H goes unanswered inside a packet the session closes the packet
    # (*E-1, which every unit refuses) and sends H again; then D
    kinds = [f[2:-1] for f in after]
    assert kinds[0] == b"H" and b"D" in kinds, after[:4]
    assert set(kinds[:kinds.index(b"D")]) <= {b"H", b"*E-1"}, after[:4]
    assert not [f for f in after if MOTION.match(f)
                and not f.startswith((b"!0L0,0,0", b"!0*E-1\r"))]   # the closer is refused
    assert state["physical"] == stopped[0], "the axes moved after H"
    assert image.read_bytes() == bytes(data), "EEPROM not as found"
    assert state["status"][:6] == ["00"] * 6
    assert (tmp_path / "reports").exists(), out.decode() + err.decode()
    (folder,) = [p for p in (tmp_path / "reports").iterdir() if not p.name.startswith(".")]
    report = json.loads((folder / "results.json").read_text())
    assert report["interrupted"] is True and proc[0].returncode != 0
    assert b"PASS" not in out.splitlines()[-2], out.decode()   # the verdicts' line
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


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM, signal.SIGHUP],
                         ids=["SIGINT", "SIGTERM", "SIGHUP"])
@pytest.mark.parametrize("where", ["case", "machine"])
def test_a_signal_inside_the_quiet_line_wait_sends_nothing_before_h(tmp_path, sig, where):
    """The answer to a frame is lost; a second later (the frame's timeout has passed, the
    2.5 s wait for a quiet line has not) the signal comes: the frame the link was about to
    send after the wait never goes out, H does."""
    trigger = in_machine(3) if where == "machine" else counting(rb"!0EW", 1)
    after, _, report = ctrl_c_run(tmp_path, trigger, sig=sig, after_s=1.0, drop=True)
    assert after[0].startswith(b"!0H") and report["interrupted"] is True


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
@pytest.mark.parametrize("drop", [False, True], ids=["in-flight", "quiet-wait"])
def test_a_signal_during_diff_sends_h_then_d_first(tmp_path, sig, drop):
    """diff's search: a signal while a frame is in flight, or (its answer lost) inside the
    wait for a quiet line: H and D are the next frames, the search stops, nothing says
    PASS."""
    after, _, report = ctrl_c_run(tmp_path, counting(rb"!0(L|C)", 20), sig=sig,
                                  after_s=1.0 if drop else 0.0, drop=drop, command=DIFF)
    assert after[0].startswith(b"!0H")
    assert [r["verdict"] for r in report["results"]] != ["PASS"]
