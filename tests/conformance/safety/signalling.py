"""A process tree signalled at a drawn instant — the n-th frame a unit answers — while it
drives two emulated units behind proxies, and what the units' lines must show after it:
`H` at once, nothing that can move before it, then `D`."""

from __future__ import annotations

import os
import re
import subprocess
import time
from collections.abc import Callable
from contextlib import ExitStack
from dataclasses import dataclass, field

from tests.conformance.safety.proxy import Proxy, unit_behind_proxy
from tests.processes import descendants

#: frames the unit answers (after `*S` and a packet's members the suite does not wait)
ANSWERED = re.compile(rb"!0(?!\*S|C|B)")
#: frames that can start motion (the session's L0,0,0 polls and the *E-1 closer do not)
MOTION = re.compile(rb"!\d(L|C|G|W|\*E|SW6)")
#: how long the signal may take to reach a process of the tree and its H the line
HALT_SECONDS = 1.0
#: how soon after the signal a frame read may still have been written before a child of
#: the signalled process learnt of it
IN_FLIGHT_SECONDS = 0.005


@dataclass
class Signalled:
    """What the run did: its status and output, the units' proxies, the instant of the
    signal and every process the tree had started by then."""

    status: int
    out: str
    proxies: tuple[Proxy, Proxy]
    instant: float | None
    started: list[int] = field(default_factory=list)


def signal_at_frame(argv: Callable[[str, str], list[str]], sig: int, nth: int,
                    cwd: str | None = None, deadline: float = 300.0) -> Signalled:
    """Run ``argv(first_port, other_port)``; at the ``nth`` frame the first unit answers,
    send ``sig`` to the run's main process (alone, as a CI's cancel does)."""
    proc: list[subprocess.Popen] = []
    instant: list[float] = []
    started: list[int] = []
    answered: list[int] = []

    def on_frame(i: int, frame: bytes) -> None:
        if proc and not instant and ANSWERED.match(frame):
            answered.append(i)
            if len(answered) == nth:
                started.extend(descendants(proc[0].pid))
                instant.append(time.monotonic())
                os.kill(proc[0].pid, sig)

    with ExitStack() as units:
        first = units.enter_context(unit_behind_proxy("--model", "GVE84-100",
                                                      on_frame=on_frame))[1]
        other = units.enter_context(unit_behind_proxy("--model", "GVE84-100"))[1]
        proc.append(subprocess.Popen(argv(first.path, other.path), cwd=cwd,
                                     stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                     stdin=subprocess.DEVNULL))
        try:
            out = proc[0].communicate(timeout=deadline)[0].decode(errors="replace")
        finally:
            if proc[0].poll() is None:
                proc[0].kill()
                proc[0].wait()
    return Signalled(proc[0].returncode, out, (first, other),
                     instant[0] if instant else None, started)


def assert_halted_first(frames: list[tuple[float, bytes]], signalled: float) -> None:
    """After the signal: `H` within HALT_SECONDS, nothing that can move before it, then
    `D`. The signal reaches a child through its parent, and each proxy stamps a frame as
    it reads it, on a thread of its own: a first frame read within IN_FLIGHT_SECONDS of
    the signal may have been on its way before the child knew (any frame); the other
    frames a child sends in that millisecond or two are its known state's (never
    motion), and are allowed."""
    after = [(t, f) for t, f in frames if t > signalled]
    if not after:
        return                                   # that process had ended, or not begun
    halt = next((i for i, (_, f) in enumerate(after) if f[2:3] == b"H"), None)
    assert halt is not None, [f for _, f in after[:6]]
    assert after[halt][0] - signalled < HALT_SECONDS, after[:halt + 1]
    in_flight = 1 if after[0][0] - signalled < IN_FLIGHT_SECONDS else 0
    assert not [f for _, f in after[in_flight:halt] if MOTION.match(f)
                and not f.startswith((b"!0L0,0,0", b"!0*E-1\r"))], after[:halt]
    assert any(f[2:3] == b"D" for _, f in after[halt:]), after
