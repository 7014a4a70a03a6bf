"""Driving programs as a technician would: the suite on a pseudo-terminal (its questions
read and answered), and an emulated unit on its own pty with the test rig's control
channel at hand (where the technician's hand grounds an input)."""

from __future__ import annotations

import os
import select
import subprocess
import sys
import time

#: the longest a test waits for an expected text (a deadline, never a sleep)
DEADLINE = 60.0


class Terminal:
    """A program whose standard input, output and error are a pseudo-terminal."""

    def __init__(self, argv: list[str]) -> None:
        self.master, slave = os.openpty()
        self.proc = subprocess.Popen(argv, stdin=slave, stdout=slave, stderr=slave,
                                     close_fds=True)
        os.close(slave)
        self.seen = ""
        self.pos = 0             # where the next expect looks from

    def _read(self, end: float, what: str) -> None:
        """Whatever the program writes next, waiting up to the instant ``end``."""
        left = end - time.monotonic()
        assert left > 0, f"waited for {what}; seen:\n{self.seen[-2000:]}"
        ready, _, _ = select.select([self.master], [], [], left)
        if ready:
            try:
                data = os.read(self.master, 4096)
            except OSError:                     # the program ended: EIO on Linux
                data = b""
            assert data, f"ended before {what}; seen:\n{self.seen[-2000:]}"
            self.seen += data.decode("utf-8", "replace")

    def expect(self, text: str, deadline: float = DEADLINE) -> str:
        """Read until ``text`` appears after the last text expected; what came between."""
        end = time.monotonic() + deadline
        while text not in self.seen[self.pos:]:
            self._read(end, repr(text))
        start, self.pos = self.pos, self.seen.index(text, self.pos) + len(text)
        return self.seen[start:self.pos]

    def expect_any(self, *texts: str, deadline: float = DEADLINE) -> str:
        """Read until one of ``texts`` appears; the one that appeared first."""
        end = time.monotonic() + deadline
        while True:
            found = sorted((i, t) for t in texts if (i := self.seen.find(t, self.pos)) >= 0)
            if found:
                self.expect(found[0][1])
                return found[0][1]
            self._read(end, " or ".join(map(repr, texts)))

    def answer(self, line: str) -> None:
        os.write(self.master, line.encode() + b"\n")

    def finish(self, deadline: float = DEADLINE) -> int:
        """Read to the end; the exit status."""
        end = time.monotonic() + deadline
        while True:
            ready, _, _ = select.select([self.master], [], [], max(0.0, end - time.monotonic()))
            assert ready or time.monotonic() < end, "the program did not end"
            try:
                data = os.read(self.master, 4096)
            except OSError:
                break
            if not data:
                break
            self.seen += data.decode("utf-8", "replace")
        os.close(self.master)
        return self.proc.wait(deadline)


class EmulatedUnit:
    """``python -m emulator --pty``: the path of its pty, and its rig's control channel."""

    def __init__(self, model: str) -> None:
        self.model = model
        self.proc = subprocess.Popen([sys.executable, "-m", "emulator", "--model", model,
                                      "--pty"], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     stderr=subprocess.DEVNULL, text=True)
        self._path = ""

    @property
    def path(self) -> str:
        """The pty's path, the first line the emulator prints (read once it is needed,
        so that several units start side by side)."""
        if not self._path:
            self._path = self.proc.stdout.readline().strip()
        return self._path

    def rig(self, command: str) -> str:
        """A control-channel command (``in 1 FE``: IN0 grounded); its answer."""
        self.proc.stdin.write(command + "\n")
        self.proc.stdin.flush()
        return self.proc.stdout.readline()

    def close(self) -> None:
        self.proc.terminate()
        self.proc.wait(10)


def suite(*args: str) -> list[str]:
    """The command line of the suite itself, printing every case uncoloured, as the
    prompts' tests read the case lines between the questions."""
    return [sys.executable, "-m", "conformance", "-v", "--color", "never", *args]
