"""What a long job shows while it runs: the suite's run (a line per case), and the
subcommands' steps (a mutant hunted, a reading tried, a fleet's target done, diff's
sequences).

- On a terminal: a progress bar (tqdm: steps done/total, elapsed, estimate) and above it
  only the lines that need reading: every case's verdict but PASS and MISSING, every
  step that is not routine (``-v``: every line).
- Elsewhere (a CI log, a pipe): the same lines, numbered ``[done/total]``, and no bar;
  where routine lines are not shown, a line at every tenth of the way
  (``[130/1296] 10 %, 4.1 s``), so that a log shows the job is moving.
- A long job (``heartbeat``: the mutation and fairness scores) shows it is moving at
  least every HEARTBEAT seconds: the bar's clock redrawn, or a line in a log
  (``[0/31] 0 % in 5.0 s, still working``).
- ``-q``: nothing (the job prints its recap and last line only).

The verdict of each line is coloured when colour is on (colour.py). The bar is cleared
when the job ends, Ctrl-C included: while it is shown the terminal does not echo ``^C``,
whose two characters would wrap a full-width bar onto a line of its own and leave the
old bar above the summary.
"""

from __future__ import annotations

import contextlib
import os
import sys
import threading
import time
from collections.abc import Callable
from typing import TextIO

from tqdm import tqdm

from conformance.cli.colour import paint
from conformance.run.runner import CaseResult
from conformance.verdicts.explain import reason
from conformance.verdicts.verdict import MISSING, PASS, UNTESTED

#: verdicts a terminal does not show a line for (the bar counts them)
_ROUTINE = (PASS, MISSING)
#: a log without routine lines says how far the job is at every tenth of it
_TENTHS = 10
#: a long job (a mutant, a reading: tens of seconds each) shows it is moving at least
#: this often (seconds): a line in a log, the bar's clock redrawn on a terminal
HEARTBEAT = 5.0


def describe(r: CaseResult, colour: bool = False) -> str:
    """One console line for a result: its verdict, ID, profile and why it is not a PASS
    (the deciding check's rule, tag, what was seen and wanted: conformance/verdicts/explain.py)."""
    line = f"{paint(r.verdict, f'{r.verdict:15}', colour)} {r.id} [{r.profile}]"
    if r.verdict != PASS and (r.verdict not in UNTESTED or r.notes):
        line += f"  -- {reason(r).line()}"
    return line


class Progress:
    """``total`` steps of ``unit`` (a case run, a mutant, a sequence...). ``quiet``: no
    lines and no bar; ``verbose``: every line, on a terminal too; ``every_step``: a log
    shows routine lines too (a few long steps: a mutant, a reading); ``colour``:
    coloured verdicts; ``status``: what a log's tenth line says besides the count."""

    def __init__(self, total: int, *, unit: str = "case", quiet: bool = False,
                 verbose: bool = False, colour: bool = False, every_step: bool = False,
                 stream: TextIO | None = None, terminal: bool | None = None,
                 refresh: float = 0.1, status: Callable[[], str] | None = None,
                 heartbeat: float | None = None) -> None:
        self.stream = stream or sys.stdout
        self.total = max(total, 1)
        self.unit = unit
        self.done = 0
        self.quiet = quiet
        self.verbose = verbose
        self.colour = colour
        self.every_step = every_step
        self.status = status
        self.started = time.perf_counter()
        self._tenth = 0
        terminal = self.stream.isatty() if terminal is None else terminal
        self._echo = _NoControlEcho() if terminal and not quiet else None
        # the bar redraws at most every ``refresh`` seconds
        self.bar = tqdm(total=total, unit=unit, file=self.stream, dynamic_ncols=True,
                        leave=False, mininterval=refresh) if terminal and not quiet else None
        self._lock = threading.Lock()
        self._said = time.perf_counter()            # when the job last showed something
        self._stop = threading.Event()
        self._beat: threading.Thread | None = None
        if heartbeat is not None and not quiet:
            self._beat = threading.Thread(target=self._heartbeat, args=(heartbeat,),
                                          daemon=True, name="progress-heartbeat")
            self._beat.start()

    def _heartbeat(self, every: float) -> None:
        """Every ``every`` seconds without a line: the bar's clock redrawn, or in a log
        a line saying how far the job is and that it is still working."""
        # woken a little before ``every`` has passed since the last line or redraw, so
        # that a loaded machine's late wake-up still shows one within ``every``
        soon = 0.9 * every
        while not self._stop.wait(max(0.0, self._said + soon - time.perf_counter())):
            with self._lock:
                if self._stop.is_set():
                    return
                if time.perf_counter() - self._said < soon:
                    continue
                if self.bar is not None:
                    self.bar.refresh()
                    self._said = time.perf_counter()
                else:
                    self._print(f"[{self.done}/{self.total}] {100 * self.done // self.total}"
                                f" % in {time.perf_counter() - self.started:.1f} s, still "
                                f"working")

    def print(self, text: str) -> None:
        """A line above the bar (or a plain line)."""
        with self._lock:
            self._print(text)

    def _print(self, text: str) -> None:
        self._said = time.perf_counter()
        try:
            if self.bar is not None:
                self.bar.write(text, file=self.stream)
            else:
                print(text, file=self.stream, flush=True)
        except BrokenPipeError:
            # its reader is gone (`| head`): the job goes on, its lines go nowhere
            self.quiet = True
            with contextlib.suppress(OSError, ValueError):
                os.dup2(os.open(os.devnull, os.O_WRONLY), self.stream.fileno())

    def step(self, text: str | None = None, *, routine: bool = False, advance: int = 1,
             label: str | None = None) -> None:
        """``advance`` steps done; ``text`` the line they give (``routine``: one a
        terminal and, unless ``every_step``, a log leave out); ``label`` shown beside
        the bar (the profile being run)."""
        shown = text is not None and (
            not routine or self.verbose or (self.bar is None and self.every_step))
        self.advance_to(self.done + advance, label=label, shown=shown)
        if self.quiet or text is None or not shown:
            return
        if self.bar is not None:
            self.print(text)
        else:
            self.print(f"[{self.done:{len(str(self.total))}}/{self.total}] {text}")

    def advance_to(self, done: int, *, label: str | None = None, shown: bool = False
                   ) -> None:
        """``done`` steps done so far (diff: sequences or seconds); a log that showed no
        line for them says so at every tenth of the way."""
        done = min(done, self.total)
        if self.bar is not None:
            if label is not None:
                self.bar.set_description_str(label, refresh=False)
            self.bar.update(done - self.done)
        self.done = max(self.done, done)
        tenth = self.done * _TENTHS // self.total
        if tenth <= self._tenth:
            return
        self._tenth = tenth
        if self.bar is None and not self.quiet and not shown:
            more = f": {self.status()}" if self.status else ""
            self.print(f"[{self.done}/{self.total}] {100 * self.done // self.total} % "
                       f"in {time.perf_counter() - self.started:.1f} s{more}")

    def result(self, r: CaseResult) -> None:
        """A case run done: its line (every verdict but PASS and MISSING)."""
        self.step(describe(r, self.colour), routine=r.verdict in _ROUTINE, label=r.profile)

    def close(self) -> None:
        """The bar gone from the screen, the terminal's echo as it was."""
        self._stop.set()
        if self._beat is not None and self._beat is not threading.current_thread():
            self._beat.join()
            self._beat = None
        if self.bar is not None:
            self.bar.close()
            with contextlib.suppress(OSError, ValueError):
                self.stream.write("\r\x1b[2K")         # whatever the last redraw left
                self.stream.flush()
            self.bar = None
        if self._echo is not None:
            self._echo.restore()
            self._echo = None

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class _NoControlEcho:
    """The terminal on standard input stops echoing control characters (``^C``) until
    :meth:`restore`; nothing happens where standard input is not a terminal."""

    def __init__(self) -> None:
        self.saved: list | None = None
        try:
            import termios
            fd = sys.stdin.fileno()
            if not sys.stdin.isatty():
                return
            self.saved = termios.tcgetattr(fd)
            quiet = termios.tcgetattr(fd)
            quiet[3] &= ~termios.ECHOCTL
            termios.tcsetattr(fd, termios.TCSANOW, quiet)
        except (ImportError, OSError, ValueError, AttributeError):
            self.saved = None

    def restore(self) -> None:
        if self.saved is None:
            return
        import termios
        with contextlib.suppress(OSError, ValueError):
            termios.tcsetattr(sys.stdin.fileno(), termios.TCSANOW, self.saved)
        self.saved = None
