"""The program behind an ``exec:`` target: started in a process group of its own (so
that Ctrl-C on the terminal reaches the suite alone, which halts the unit before the
program is stopped), its standard output read line by line (when asked for, or by a
thread in the background once :meth:`Program.read_in_background` is called), its
standard input written line by line, its standard error kept for the one line that says
why it failed.

Stopping it (:meth:`Program.stop`) asks first (``quit`` on standard input, docs/rig.md),
then terminates and finally kills its whole process group, each with a bounded wait, and
reaps it: no zombie, no orphan. Every program still running when the interpreter exits
is stopped the same way.
"""

from __future__ import annotations

import atexit
import contextlib
import os
import queue
import select
import shlex
import signal
import subprocess
import tempfile
import threading
import time

from conformance.link.signals import StopSignals
from conformance.verdicts.quoting import shown

#: how long the program may take to end after ``quit``, then after SIGTERM
QUIT_SECONDS = 2.0
TERM_SECONDS = 2.0
#: lines of standard output held for a reader that does not take them
HELD_LINES = 1000
#: a line longer than this comes in pieces of this length (garbage stays bounded)
LINE_LIMIT = 1 << 20
#: how long a line awaited with a timeout is polled for before the reader sleeps
POLL_SECONDS = 100e-6
#: a wait for the processor this long while polling means another process wanted it: the
#: reader sleeps instead (on a loaded machine polling slows everyone)
SHARED_SECONDS = 50e-6

_RUNNING: set[Program] = set()


class ProgramError(Exception):
    """The program cannot be started or did not do what an ``exec:`` target needs."""


class Program:
    """A running program: lines out (:meth:`line`), lines in (:meth:`send`)."""

    def __init__(self, command: list[str]) -> None:
        self.command = command
        self._stderr = tempfile.TemporaryFile()  # noqa: SIM115  (open while it runs)
        try:
            # a signal waits until the program is known (and stopped at exit): never a
            # Popen lost as fork_exec returns, its program running on
            with StopSignals.held():
                self.process = subprocess.Popen(
                    command, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                    stderr=self._stderr, process_group=0, close_fds=True)
                _RUNNING.add(self)
        except (OSError, ValueError) as err:
            self._stderr.close()
            reason = err.strerror if isinstance(err, OSError) and err.strerror else str(err)
            raise ProgramError(f"cannot start {command[0]!r}: {reason}") from None
        self._fd = self.process.stdout.fileno()     # read with os.read only, unbuffered
        self._pending = bytearray()                 # bytes read, not yet a whole line
        self._lines: queue.Queue[str | None] = queue.Queue()
        self._background = False
        self._eof = False
        # stop() wakes the reader through this pipe and waits for it before closing
        # standard output: a reader left blocked on a closed descriptor would read the
        # next program's output once its number is reused
        self._wake_r, self._wake_w = os.pipe()
        self._reader: threading.Thread | None = None

    # -- what it says ---------------------------------------------------------------------
    def _take(self, timeout: float | None) -> str | None:
        """The next line read from standard output itself, waiting up to ``timeout``
        seconds (None: until one comes); None when none came or the output ended. A line
        longer than LINE_LIMIT comes in pieces."""
        end: float | None = None             # (the clock read once it has to wait)
        while True:
            k = self._pending.find(b"\n")
            if k >= 0 or len(self._pending) >= LINE_LIMIT or (self._eof and self._pending):
                k = min(len(self._pending), LINE_LIMIT) if k < 0 else k
                raw = self._pending[:k]
                del self._pending[:k + 1]
                return raw.decode("utf-8", "replace").rstrip("\r")
            if self._eof:
                return None
            if timeout is not None and end is None:
                end = time.monotonic() + timeout
            left = None if end is None else max(0.0, end - time.monotonic())
            try:
                ready = self._ready(left)
                data = (b"" if self._wake_r in ready else
                        os.read(self._fd, 1 << 16) if ready else None)
            except (OSError, ValueError):              # closed by stop()
                data = b""
            if data is None:
                return None
            if not data:
                self._eof = True
            self._pending += data

    def _ready(self, left: float | None) -> list[int]:
        """The descriptors readable within ``left`` seconds (None: whenever). A reply
        awaited with a timeout (a co-simulator's, which mostly comes within tens of
        microseconds) is first polled for up to :data:`POLL_SECONDS`: a process that
        sleeps at once is woken late (tens of microseconds a time on a virtual machine,
        each of a sequence's exchanges). A reader without a timeout (the thread that
        reads a program in the background) never polls."""
        fds = [self._fd, self._wake_r]
        if left:
            began = last = time.perf_counter()
            until = began + min(left, POLL_SECONDS)
            while last < until:
                ready = select.select(fds, [], [], 0)[0]
                if ready:
                    return ready
                os.sched_yield()        # awake, yet any other process that can run runs
                now = time.perf_counter()
                if now - last > SHARED_SECONDS:
                    break               # one did: the processor is wanted, sleep
                last = now
            left = max(0.0, left - (time.perf_counter() - began))
        return select.select(fds, [], [], left)[0]

    def read_in_background(self) -> None:
        """From now on a thread reads standard output as it comes, so that the program
        never blocks on it: lines beyond HELD_LINES that nobody takes are dropped (a
        simulator in real time, whose output is its rig's replies and what else it
        prints). Until then lines are read when asked for, none dropped (a
        co-simulator's replies, docs/cosim.md)."""
        if not self._background:
            self._background = True
            self._reader = threading.Thread(target=self._read, daemon=True,
                                            name=f"exec-{self.process.pid}")
            self._reader.start()

    def _read(self) -> None:
        while (text := self._take(None)) is not None:
            if self._lines.qsize() < HELD_LINES:
                self._lines.put(text)
        self._lines.put(None)

    def line(self, timeout: float) -> str | None:
        """The next line of standard output within ``timeout`` seconds (None: none came,
        or the output ended)."""
        if not self._background:
            return self._take(timeout)
        if self._eof and self._lines.empty():
            return None
        try:
            return self._lines.get(timeout=timeout)
        except queue.Empty:
            return None

    def discard(self) -> list[str]:
        """The lines already printed and not taken (dropped)."""
        out = []
        while True:
            if not self._background:
                text = self._take(0.0)
                if text is None:
                    return out
            else:
                try:
                    text = self._lines.get_nowait()
                except queue.Empty:
                    return out
            if text is not None:
                out.append(text)

    def send(self, text: str) -> bool:
        """One line on its standard input; False when it no longer reads it."""
        stdin = self.process.stdin
        if stdin is None or stdin.closed:
            return False
        try:
            stdin.write(text.encode() + b"\n")
            stdin.flush()
        except (OSError, ValueError):
            return False
        return True

    @property
    def alive(self) -> bool:
        return self.process.poll() is None

    def wait(self, seconds: float) -> bool:
        """Wait up to ``seconds`` for it to end; True when it has."""
        try:
            self.process.wait(seconds)
        except subprocess.TimeoutExpired:
            return False
        return True

    def stderr_tail(self) -> str:
        """The last line it wrote on standard error ('' if none)."""
        with contextlib.suppress(OSError, ValueError):
            self._stderr.seek(0)
            lines = [x for x in self._stderr.read()[-4096:].decode("utf-8", "replace")
                     .splitlines() if x.strip()]
            return lines[-1].strip() if lines else ""
        return ""

    def ended(self) -> str:
        """Why it is no longer running, in one line ('' while it runs)."""
        status = self.process.poll()
        if status is None:
            return ""
        how = (f"was killed by signal {-status}" if status < 0 else
               f"exited with status {status}")
        tail = self.stderr_tail()
        return f"{shlex.join(self.command)} {how}" + (f" (stderr: {shown(tail)})" if tail else "")

    # -- the end -----------------------------------------------------------------------------
    def stop(self) -> None:
        """`quit`, then SIGTERM, then SIGKILL to its process group, each with a bounded
        wait; reaped, and whatever of its group is left ended too. Idempotent."""
        if self not in _RUNNING:
            return
        _RUNNING.discard(self)
        group = self.process.pid
        if self.alive and not (self.send("quit") and self.wait(QUIT_SECONDS)):
            for sig, seconds in ((signal.SIGTERM, TERM_SECONDS), (signal.SIGKILL, None)):
                with contextlib.suppress(ProcessLookupError, PermissionError):
                    os.killpg(group, sig)
                if self.wait(seconds if seconds is not None else TERM_SECONDS):
                    break
        self.process.wait()                            # reaped: no zombie
        _end_group(group)                              # what it started: no orphan
        with contextlib.suppress(OSError):
            os.write(self._wake_w, b"\n")
        if self._reader not in (None, threading.current_thread()):
            self._reader.join()
        for stream in (self.process.stdin, self.process.stdout):
            with contextlib.suppress(OSError, ValueError):
                if stream is not None:
                    stream.close()
        self._stderr.close()
        for end in (self._wake_r, self._wake_w):
            os.close(end)


def _end_group(group: int) -> None:
    """End the processes left in ``group`` (the program's children), gently first."""
    for sig in (signal.SIGTERM, signal.SIGKILL):
        try:
            os.killpg(group, sig)
        except (ProcessLookupError, PermissionError):
            return
        end = time.monotonic() + TERM_SECONDS
        while time.monotonic() < end:
            try:
                os.killpg(group, 0)
            except (ProcessLookupError, PermissionError):
                return
            time.sleep(0.02)


@atexit.register
def _stop_all() -> None:
    for program in list(_RUNNING):
        program.stop()
