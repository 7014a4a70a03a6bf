"""What a run shows while it runs (issue 12 items 3, 7): one line per case result, and on
a terminal a progress bar below them (tqdm: case runs done/total, elapsed, estimate);
elsewhere (a CI log, a pipe) plain lines numbered ``[done/total]``."""

from __future__ import annotations

import sys
from typing import TextIO

from tqdm import tqdm

from conformance.runner import CaseResult
from conformance.verdict import COULD_NOT_TEST, ERROR, MISSING, PASS

#: verdicts whose line gives the reason (the case's first note)
_WHY = (COULD_NOT_TEST, MISSING, ERROR)


def describe(r: CaseResult) -> str:
    """One console line for a result: its verdict, ID, profile and why it is not a PASS."""
    line = f"{r.verdict:15} {r.id} [{r.profile}]"
    if r.failed_checks:
        c = r.failed_checks[0]
        line += f"  -- {c['what']}: observed {c['observed']!r}, expected {c['expected']!r}"
    elif r.verdict in _WHY and r.notes:
        line += f"  -- {r.notes[0].splitlines()[0]}"
    return line


class Progress:
    def __init__(self, total: int, *, quiet: bool = False, stream: TextIO | None = None,
                 terminal: bool | None = None, refresh: float = 0.1) -> None:
        self.stream = stream or sys.stdout
        self.total = total
        self.done = 0
        self.quiet = quiet
        terminal = self.stream.isatty() if terminal is None else terminal
        # the bar redraws at most every ``refresh`` seconds
        self.bar = tqdm(total=total, unit="case", file=self.stream, dynamic_ncols=True,
                        leave=False, mininterval=refresh) if terminal else None

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
        if self.quiet and r.verdict == PASS:
            return
        width = len(str(self.total))
        self.print(describe(r) if self.bar is not None
                   else f"[{self.done:{width}}/{self.total}] {describe(r)}")

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
