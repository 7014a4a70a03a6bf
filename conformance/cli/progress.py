"""What a run shows while it runs.

- On a terminal: a progress bar (tqdm: case runs done/total, elapsed, estimate) and
  above it only the lines that need reading: every verdict but PASS and MISSING
  (``-v``: every case).
- Elsewhere (a CI log, a pipe): one plain line per case, numbered ``[done/total]``.
- ``-q``: nothing (the run prints its last line only).

The verdict of each line is coloured when colour is on (colour.py). The bar is cleared
when the run ends, Ctrl-C included: while it is shown the terminal does not echo ``^C``,
whose two characters would wrap a full-width bar onto a line of its own and leave the
old bar above the summary.
"""

from __future__ import annotations

import contextlib
import sys
from typing import TextIO

from tqdm import tqdm

from conformance.cli.colour import paint
from conformance.quoting import quoted
from conformance.runner import CaseResult
from conformance.verdict import COULD_NOT_TEST, ERROR, MISSING, PASS

#: verdicts whose line gives the reason (the case's first note)
_WHY = (COULD_NOT_TEST, MISSING, ERROR)
#: verdicts a terminal does not show a line for (the bar counts them)
_ROUTINE = (PASS, MISSING)


def describe(r: CaseResult, colour: bool = False) -> str:
    """One console line for a result: its verdict, ID, profile and why it is not a PASS."""
    line = f"{paint(r.verdict, f'{r.verdict:15}', colour)} {r.id} [{r.profile}]"
    if r.failed_checks:
        c = r.failed_checks[0]
        line += (f"  -- {c['what']}: observed {quoted(c['observed'])}, "
                 f"expected {quoted(c['expected'])}")
    elif r.verdict in _WHY and r.notes:
        line += f"  -- {r.notes[0].splitlines()[0]}"
    return line


class Progress:
    """``quiet``: no lines and no bar; ``verbose``: a line for every case on a terminal
    too; ``colour``: coloured verdicts."""

    def __init__(self, total: int, *, quiet: bool = False, verbose: bool = False,
                 colour: bool = False, stream: TextIO | None = None,
                 terminal: bool | None = None, refresh: float = 0.1) -> None:
        self.stream = stream or sys.stdout
        self.total = total
        self.done = 0
        self.quiet = quiet
        self.verbose = verbose
        self.colour = colour
        terminal = self.stream.isatty() if terminal is None else terminal
        self._echo = _NoControlEcho() if terminal and not quiet else None
        # the bar redraws at most every ``refresh`` seconds
        self.bar = tqdm(total=total, unit="case", file=self.stream, dynamic_ncols=True,
                        leave=False, mininterval=refresh) if terminal and not quiet else None

    def print(self, text: str) -> None:
        """A line above the bar (or a plain line)."""
        if self.bar is not None:
            self.bar.write(text, file=self.stream)
        else:
            print(text, file=self.stream, flush=True)

    def result(self, r: CaseResult) -> None:
        self.done += 1
        if self.bar is not None:
            self.bar.set_description_str(r.profile, refresh=False)
            self.bar.update(1)
        if self.quiet:
            return
        if self.bar is not None:
            if self.verbose or r.verdict not in _ROUTINE:
                self.print(describe(r, self.colour))
            return
        width = len(str(self.total))
        self.print(f"[{self.done:{width}}/{self.total}] {describe(r, self.colour)}")

    def close(self) -> None:
        """The bar gone from the screen, the terminal's echo as it was."""
        if self.bar is not None:
            self.bar.close()
            with contextlib.suppress(OSError, ValueError):
                self.stream.write("\r\x1b[2K")         # whatever the last redraw left
                self.stream.flush()
            self.bar = None
        if self._echo is not None:
            self._echo.restore()
            self._echo = None


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
