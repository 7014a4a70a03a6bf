"""The technician at the terminal (issue 12 items 2, 3): the question before the first
move, and the steps only a hand on the machine can do.

- :class:`Console`: questions on a terminal (yes/no, a choice, "do this, then Enter").
- :func:`confirm_motion`: the unit's identity, the envelope per axis and whether
  destructive tests are on, then "Move this machine?" (``--yes`` skips it).
- :class:`Hands` (``ctx.operator`` in a case): ground or release an input. On the
  emulator its test rig does it; on a real unit the operator is asked and the suite
  reads the input port back before going on. A step skipped, not verified, or with
  nobody to ask stops the case as COULD-NOT-TEST with the reason, never a FAIL.
"""

from __future__ import annotations

import signal
import sys
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import TextIO

from tqdm import tqdm

from conformance.link.interrupts import Interrupted
from conformance.link.link import Link
from conformance.verdict import CouldNotTest

#: input ports read FF with nothing connected (spec 10.3: inputs are grounded to act)
NOTHING_CONNECTED = 0xFF


class Console:
    """Questions to the person at the terminal. ``interactive`` is False when nobody can
    answer (standard input is not a terminal): every question then has no answer."""

    def __init__(self, stdin: TextIO | None = None, stdout: TextIO | None = None,
                 interactive: bool | None = None) -> None:
        self.stdin = stdin or sys.stdin
        self.stdout = stdout or sys.stdout
        self.interactive = self.stdin.isatty() if interactive is None else interactive

    def say(self, text: str) -> None:
        with tqdm.external_write_mode(file=self.stdout):    # above a progress bar
            print(text, file=self.stdout, flush=True)

    def _answer(self, prompt: str) -> str | None:
        if not self.interactive:
            return None
        with tqdm.external_write_mode(file=self.stdout), _interruptible():
            self.stdout.write(prompt)
            self.stdout.flush()
            line = self.stdin.readline()
        return None if not line else line.strip()         # end of input: no answer

    def confirm(self, question: str) -> bool:
        """Yes only for an explicit y or yes."""
        answer = self._answer(f"{question} [y/N] ")
        return answer is not None and answer.lower() in ("y", "yes")

    def choose(self, question: str, options: list[str]) -> str | None:
        """One of ``options`` (asked again until one is given), or None."""
        while True:
            answer = self._answer(f"{question} ({', '.join(options)}) ")
            if answer is None or answer in options:
                return answer
            self.say(f"  please answer one of: {', '.join(options)}")

    def step(self, instruction: str) -> bool:
        """"<instruction> now, then press Enter; s to skip": True when done, False when
        skipped (or nobody can answer)."""
        answer = self._answer(f"{instruction} now, then press Enter; s to skip: ")
        return answer is not None and answer.lower() not in ("s", "skip")


@contextmanager
def _interruptible() -> Iterator[None]:
    """Ctrl-C at a question ends the wait at once: the run counts it as it counts any
    Ctrl-C (then H and D go out), and the question raises Interrupted."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.getsignal(signal.SIGINT)

    def stop(signum: int, frame: object) -> None:
        if callable(previous):
            previous(signum, frame)
        raise Interrupted("Ctrl-C at a question")

    signal.signal(signal.SIGINT, stop)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def confirm_motion(console: Console, lines: list[str]) -> bool:
    """Show what is about to move and ask before the first frame that can move an axis."""
    console.say("\nThe suite is about to move a real machine:")
    for line in lines:
        console.say(f"  {line}")
    console.say("Keep a hand near the emergency stop; Ctrl-C halts the unit (H, then D).")
    return console.confirm("Move this machine?")


class Hands:
    """Hand steps for a case (``ctx.operator``): ``with ctx.operator.grounded(1, 0,
    "IN0 (X reference)"):`` — the input is active inside the block and released after."""

    def __init__(self, link: Callable[[], Link], console: Console | None) -> None:
        self._link = link                    # the case's current link (ctx.link)
        self.console = console               # None: no operator steps in this run
        self._levels: dict[int, int] = {}    # rig ports as the rig was told to set them

    def _rig(self, port: int, bit: int, grounded: bool) -> None:
        link = self._link()
        level = self._levels.get(port, NOTHING_CONNECTED)
        level = level & ~(1 << bit) if grounded else level | 1 << bit
        self._levels[port] = level
        link.rig.set_input(port, level)

    def _read(self, port: int) -> int | None:
        r = self._link().send(f"I{port}")
        if r is None or r.code is None or r.code & 7 or not r.values:
            return None
        try:
            return int(r.values[0], 16)
        except ValueError:
            return None

    def _by_hand(self, port: int, bit: int, what: str, grounded: bool) -> None:
        verb = "Ground" if grounded else "Release"
        want = 0 if grounded else 1
        level = self._read(port)
        if level is not None and (level >> bit & 1) == want:
            return                                   # already so: nothing to ask
        if self.console is None or not self.console.interactive:
            raise CouldNotTest(f"needs a hand: {verb.lower()} input IN{bit} ({what}); "
                               "run on a terminal with --operator, or on the emulator")
        instruction = f"{verb} input IN{bit} ({what})"
        if not self.console.step(instruction):
            raise CouldNotTest(f"{instruction}: skipped by the operator")
        level = self._read(port)
        if level is None or (level >> bit & 1) != want:
            shown = "nothing" if level is None else f"{level:02X}"
            raise CouldNotTest(f"{instruction}: not verified, I{port} reads {shown} "
                               f"(IN{bit} should read {want})")
        self.console.say(f"  verified: I{port} = {level:02X}")

    def _set(self, port: int, bit: int, what: str, grounded: bool) -> bool:
        if self._link().rig is not None:
            self._rig(port, bit, grounded)
        else:
            self._by_hand(port, bit, what, grounded)
        return True

    def ground(self, port: int, bit: int, what: str) -> bool:
        """Make input IN<bit> of port I<port> active (grounded); True once verified."""
        return self._set(port, bit, what, grounded=True)

    def release(self, port: int, bit: int, what: str) -> bool:
        """Disconnect input IN<bit> again (reads 1); True once verified."""
        return self._set(port, bit, what, grounded=False)

    @contextmanager
    def grounded(self, port: int, bit: int, what: str) -> Iterator[None]:
        self.ground(port, bit, what)
        try:
            yield
        finally:
            self.release(port, bit, what)
