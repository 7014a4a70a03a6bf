"""Ctrl-C (SIGINT), SIGTERM and SIGHUP during a run: the stop signals.

The first SIGINT (or SIGTERM, SIGHUP) does not raise where it lands: it is counted, the
frame in flight gets its answer (or times out), and the link raises
:class:`Interrupted` before the next frame, so that the next frame on the line is the
session's `H`, then `D`. A signal
during the restorations that follow stops them the same way (`H`, `D` again, the rest
skipped). A third signal raises KeyboardInterrupt at once.

Outside a run (parsing the command line, opening ports, asking the operator) the three
signals alike raise KeyboardInterrupt where they land (:meth:`StopSignals.alike`), so
that a job ends the same way whichever of them came; a process that starts others (a
program, a worker, a fleet's member) does so with the signals held
(:meth:`StopSignals.held`), so that each signal finds it known and passes on to it.

A link asks whether it may write and writes with the signals held back between the two
(:meth:`StopSignals.writing`): while the run's own handler is installed
(:meth:`StopSignals.catching`), that is a flag its handler reads, set once per write;
only where another handler is installed are the handlers swapped around the write.
"""

from __future__ import annotations

import _signal
import contextlib
import signal
import threading
from collections.abc import Iterator


class Interrupted(KeyboardInterrupt):
    """Raised by the link before a frame once Ctrl-C was pressed: no frame of a case, a
    teardown or a machine goes out after the signal."""


#: the signals that stop a run as Ctrl-C does: a CI job's timeout and a closed terminal
#: send SIGTERM and SIGHUP, and the machine must halt for them too
STOPPING = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)
_STOPPING_NUMBERS = tuple(int(sig) for sig in STOPPING)


class StopSignals:
    """The run's stop signals (Ctrl-C, SIGTERM, SIGHUP) as counted, shared by every
    session of the run."""

    #: signals after which KeyboardInterrupt is raised wherever the program is
    HARD = 3

    def __init__(self) -> None:
        self.count = 0        # signals received
        self.handled = 0      # signals the sessions have answered with H and D
        self._holding = False     # a write is under way: signals are counted after it
        self._deferred = 0        # signals that came meanwhile
        self._caught = False      # this object's handler installed (catching)
        self._writing = _Writing(self)

    @property
    def pending(self) -> bool:
        """A signal that no `H` has answered yet."""
        return self.count > self.handled

    @property
    def stopped(self) -> bool:
        return self.count > 0

    def signal(self, *_: object) -> None:
        """The handler (:meth:`catching`): a signal counted, or, during a write, counted
        once the write is over (:meth:`writing`)."""
        if self._holding:
            self._deferred += 1
            return
        self._count()

    def _count(self) -> None:
        self.count += 1
        if self.count >= self.HARD:
            raise KeyboardInterrupt

    def writing(self) -> contextlib.AbstractContextManager[object]:
        """The block asks :meth:`bars` and writes: a signal that comes meanwhile lands
        after it (before the question, nothing is written; after, the bytes went out).
        While this object's handler is installed (:meth:`catching`), a flag its handler
        reads; else the handlers are swapped for the block (:meth:`held`)."""
        if self._caught and threading.current_thread() is threading.main_thread() \
                and all(_signal.getsignal(sig) == self.signal for sig in _STOPPING_NUMBERS):
            return self._writing
        return self.held()

    def bars(self, *, own: bool = False) -> bool:
        """Whether a frame may not go out now: a signal no `H` has answered yet, or any
        signal at all unless the session sends its own frames (``own``)."""
        return self.pending or (self.stopped and not own)

    def handle(self) -> None:
        """The sessions sent H and D for every signal so far."""
        self.handled = self.count

    @staticmethod
    @contextlib.contextmanager
    def held() -> Iterator[None]:
        """The stopping signals held back while the block runs (main thread only): one
        that comes meanwhile is delivered when it ends, to the handler it was meant for.
        The link asks whether it may write and writes inside one such block, so a signal
        lands either before the question (nothing is written) or after the bytes went
        out, never in between."""
        if threading.current_thread() is not threading.main_thread():
            yield
            return
        # The handlers are swapped for a recorder, and what it recorded is handed to the
        # real handlers when the block ends: Python runs a handler in the main thread
        # whichever thread the signal reached, and one that lands while a program is
        # being started runs as soon as fork_exec returns (seen on a loaded machine, the
        # program started and its Popen lost). Not a signal mask: a program started
        # inside the block would inherit it through exec and never see SIGINT, SIGTERM
        # or SIGHUP (a fleet's member, a host program, a simulator).
        caught: list[int] = []
        # (_signal's own calls: signal.signal wraps each in enum conversions that cost
        # ten times the call, and a link asks for this block around every write)
        handlers = {sig: _signal.signal(sig, lambda sig, _: caught.append(sig))
                    for sig in _STOPPING_NUMBERS}
        try:
            yield
        finally:
            for sig, handler in handlers.items():
                _signal.signal(sig, handler)
            for sig in caught:
                _deliver(sig, handlers[sig])

    @staticmethod
    @contextlib.contextmanager
    def alike() -> Iterator[None]:
        """SIGTERM and SIGHUP do what SIGINT does by default while the block runs:
        KeyboardInterrupt in the main thread (a run inside counts all three instead)."""
        if threading.current_thread() is not threading.main_thread():
            yield
            return
        previous = {sig: signal.signal(sig, signal.default_int_handler)
                    for sig in STOPPING if sig != signal.SIGINT}
        try:
            yield
        finally:
            for sig, handler in previous.items():
                signal.signal(sig, handler)

    @contextlib.contextmanager
    def catching(self) -> Iterator[StopSignals]:
        """SIGINT, SIGTERM and SIGHUP count here while the block runs (main thread only;
        elsewhere the default behaviour stays)."""
        if threading.current_thread() is not threading.main_thread():
            yield self
            return
        previous = {sig: signal.signal(sig, self.signal) for sig in STOPPING}
        self._caught = True
        try:
            yield self
        finally:
            self._caught = False
            for sig, handler in previous.items():
                signal.signal(sig, handler)


class _Writing:
    """The block of :meth:`StopSignals.writing` under the run's own handler: a flag."""

    def __init__(self, stops: StopSignals) -> None:
        self.stops = stops

    def __enter__(self) -> None:
        self.stops._holding = True

    def __exit__(self, *exc: object) -> None:
        stops = self.stops
        stops._holding = False
        deferred, stops._deferred = stops._deferred, 0
        for _ in range(deferred):
            stops._count()


def _deliver(sig: int, handler: object) -> None:
    """Hand a signal held back by :meth:`StopSignals.held` to the handler it was meant for."""
    if callable(handler):
        handler(sig, None)
    elif handler == signal.SIG_DFL:
        signal.raise_signal(sig)
