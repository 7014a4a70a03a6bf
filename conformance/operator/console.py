"""The technician at the terminal: the question before the first move, and the hand
steps (conformance/operator/hands.py asks them, reads the unit back and gives up).

- :class:`Console`: questions on a terminal (yes/no, a choice, a hand step, what the
  person sees).
- :class:`HandStep`: one thing a hand at the unit does, with its prompt.
- :func:`confirm_motion`: the unit's identity, the envelope per axis and whether
  destructive tests are on, then "Move this machine?" (``--yes`` skips it).
"""

from __future__ import annotations

import signal
import sys
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from typing import TextIO

from tqdm import tqdm

from conformance.link.signals import Interrupted


@dataclass(frozen=True)
class HandStep:
    """One step for a hand at the unit. ``kind`` is ``input`` (port ``port`` should then
    read ``level``), ``power-on`` or ``outputs`` (a question: which outputs are on);
    ``prompt`` is what the technician reads, ``skip`` the answers that skip it."""

    kind: str
    instruction: str
    prompt: str
    skip: tuple[str, ...] = ("s", "skip")
    port: int | None = None
    level: int | None = None


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

    def hand_step(self, step: HandStep) -> bool:
        """The step's prompt: True when done (Enter), False when skipped (or nobody can
        answer)."""
        answer = self._answer(step.prompt)
        return answer is not None and answer.lower() not in step.skip

    def observe(self, step: HandStep) -> str | None:
        """The step's question about what the person sees; the answer (None: none)."""
        return self._answer(step.prompt)


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
