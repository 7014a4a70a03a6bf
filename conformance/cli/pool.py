"""Jobs side by side in worker processes (or in this process for one job), stopped
alike by SIGINT, SIGTERM and SIGHUP: the jobs of `mutation` and `fairness`.

A stopping signal to this process (Ctrl-C, a CI's cancel, a closed terminal) is counted
as a run counts it (link/interrupts.py) and passed on at once to every worker; a worker
that gets one — passed on, or sent to it alone, or to the whole process group by a
terminal — ends at once, the job it ran with it (its units are the embedded emulator's,
in its own memory: nothing moves, nothing is left to put back), its pipe closing says so.
Either way the map ends: the results so far are the caller's, :attr:`Workers.interrupted`
says why there are no more, every worker has ended, and nobody prints a traceback. A
worker whose parent is gone (killed outright) ends as if signalled: no orphan runs on.

One job runs in this process; a signal raises :class:`Stopped` where the job stands (one
that lands where Python cannot raise, in a finalizer, is delivered again at once).

A time limit (``seconds``) ends the map as a signal would, the job under way with it
(raised where it stands in this process, the workers stopped), and says so in
:attr:`Workers.timed_out` instead of :attr:`Workers.interrupted`.
"""

from __future__ import annotations

import contextlib
import multiprocessing
import os
import signal
import sys
import threading
import time
import traceback
from collections import Counter
from collections.abc import Callable, Iterable, Iterator
from multiprocessing.connection import Connection, wait
from typing import Any

from conformance.cli.usage import INTERRUPTED
from conformance.link.signals import STOPPING, StopSignals

#: how long the workers may take to end once stopped, before they are killed
ENDING_SECONDS = 10.0


class Stopped(BaseException):
    """Raised in a job where a stopping signal lands: no ``except Exception`` (nor a
    run's ``except KeyboardInterrupt``, which would go on with the next case) takes it."""


class WorkerFailed(RuntimeError):
    """A job raised an exception in its worker: its traceback, as the worker printed it."""


def _leave(*_: object) -> None:
    """A worker's handler: it ends at once, its pipe closing (no reply is cut: replies go
    out with the signals held)."""
    os._exit(INTERRUPTED)


#: how soon a swallowed Stopped is raised again (seconds): once the hook has returned
_AGAIN = 0.001


@contextlib.contextmanager
def _redelivered(which: Callable[[], int]) -> Iterator[None]:
    """A Stopped that a finalizer or a callback swallowed ("Exception ignored in ...")
    is raised again, where Python can raise it: the signal that raised it (``which()``)
    sent once more from another thread, so that its handler runs after the hook has
    returned (raised inside the hook, it would be swallowed again). The signal is not
    lost, nothing is printed."""
    before = sys.unraisablehook

    def hook(unraisable: Any) -> None:
        if isinstance(unraisable.exc_value, Stopped):
            again = threading.Timer(_AGAIN, os.kill, (os.getpid(), which()))
            again.daemon = True
            again.start()
        else:
            before(unraisable)

    sys.unraisablehook = hook
    try:
        yield
    finally:
        sys.unraisablehook = before


class _Stopping(StopSignals):
    """This process's signals while the jobs run: counted, and each passed on at once to
    every worker (from the handler itself: no frame of theirs waits for a loop here)."""

    def __init__(self, pids: Callable[[], list[int]]) -> None:
        super().__init__()
        self.pids = pids

    def signal(self, *_: object) -> None:
        for pid in self.pids():
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGTERM)
        super().signal()


class Workers:
    """``map`` of a function over items, ``jobs`` at a time (see the module's text)."""

    def __init__(self, jobs: int, seconds: float | None = None) -> None:
        self.jobs = jobs
        self.seconds = seconds
        self.interrupted = False
        self.timed_out = False      # the time limit ended the map
        self.failed = ""            # the traceback of a job that raised
        self._processes: list[multiprocessing.Process] = []
        self._conns: list[Connection] = []            # to each worker

    def __enter__(self) -> Workers:
        return self

    def __exit__(self, *exc: object) -> None:
        self._end()

    def map(self, fn: Callable[[Any], Any], items: Iterable[Any],
            lane: Callable[[Any], str] | None = None) -> Iterator[Any]:
        """The results of ``fn`` on each item, in the order of the items, until a stopping
        signal ends the map (then :attr:`interrupted`). A job that raised raises
        WorkerFailed here once the workers have ended. With ``lane``, the items of each
        lane run ``jobs`` at a time, the lanes side by side (jobs that mostly wait beside
        jobs that work)."""
        todo = list(enumerate(items))
        if self.jobs <= 1 or len(todo) <= 1:
            yield from self._here(fn, [item for _, item in todo])
            return
        yield from self._there(fn, todo, lane or (lambda _: ""))

    # -- one job: in this process --------------------------------------------------------------
    def _here(self, fn: Callable[[Any], Any], items: list[Any]) -> Iterator[Any]:
        working = False                 # inside fn: a signal ends it where it stands

        def stop(*_: object) -> None:
            self.interrupted = True
            if working:
                raise Stopped

        def time_up(*_: object) -> None:
            self.timed_out = True
            if working:
                raise Stopped

        before = {sig: signal.signal(sig, stop) for sig in STOPPING}
        if self.seconds is not None:
            before[signal.SIGALRM] = signal.signal(signal.SIGALRM, time_up)
            signal.setitimer(signal.ITIMER_REAL, self.seconds)
        try:
            for item in items:
                if self.interrupted or self.timed_out:
                    return
                try:
                    working = True
                    with _redelivered(lambda: signal.SIGALRM if self.timed_out
                                      else signal.SIGTERM):
                        result = fn(item)
                    working = False
                except Stopped:
                    working = False
                    return
                yield result
        finally:
            if self.seconds is not None:
                signal.setitimer(signal.ITIMER_REAL, 0)
                if before[signal.SIGALRM] in (signal.SIG_DFL, None):
                    # a late one (redelivered) must not end the process as SIGALRM would
                    before[signal.SIGALRM] = signal.SIG_IGN
            for sig, handler in before.items():
                signal.signal(sig, handler)

    # -- several: in worker processes ----------------------------------------------------------
    def _there(self, fn: Callable[[Any], Any], todo: list[tuple[int, Any]],
               lane: Callable[[Any], str]) -> Iterator[Any]:
        stopping = _Stopping(lambda: [p.pid for p in self._processes if p.pid])
        try:
            with stopping.catching():
                yield from self._run(fn, todo, lane, stopping)
                self.interrupted = self.interrupted or stopping.stopped
                self._end()
        except KeyboardInterrupt:                   # a third signal: no more waiting
            self.interrupted = True
            for process in self._processes:
                process.kill()
        self._end()
        if self.failed:
            raise WorkerFailed(self.failed)

    def _run(self, fn: Callable[[Any], Any], todo: list[tuple[int, Any]],
             lane: Callable[[Any], str], stopping: StopSignals) -> Iterator[Any]:
        context = multiprocessing.get_context()
        idle: list[Connection] = []
        busy: dict[Connection, int] = {}
        done: dict[int, Any] = {}
        lanes = {index: lane(item) for index, item in todo}
        per_lane = Counter(lanes.values())
        running = dict.fromkeys(per_lane, 0)            # jobs under way, per lane
        for _ in range(sum(min(self.jobs, n) for n in per_lane.values())):
            here, there = context.Pipe()
            process = context.Process(target=_serve, args=(there,), daemon=True)
            # started with the signals held: a worker exists before one is passed on
            with StopSignals.held():
                process.start()
                self._processes.append(process)
            there.close()
            idle.append(here)
            self._conns.append(here)
        pending, following = list(todo), 0
        deadline = None if self.seconds is None else time.monotonic() + self.seconds
        while (pending or busy) and not stopping.stopped and not self.failed:
            if deadline is not None and time.monotonic() >= deadline:
                self.timed_out = True           # _end stops the workers under way
                return
            for job in list(pending):
                index, item = job
                if not idle:
                    break
                if running[lanes[index]] >= self.jobs:
                    continue                         # its lane is full: a later one may go
                conn = idle.pop()
                pending.remove(job)
                try:
                    conn.send((fn, item))
                except OSError:                      # it ended meanwhile: as if signalled
                    self.interrupted = True
                    stopping.signal()
                    break
                busy[conn] = index
                running[lanes[index]] += 1
            for conn in wait(list(busy), timeout=0.2):
                index = busy.pop(conn)
                running[lanes[index]] -= 1
                try:
                    outcome, value = conn.recv()
                except (EOFError, OSError):
                    outcome, value = "stopped", None     # killed: as if signalled
                if outcome == "done":
                    done[index] = value
                    idle.append(conn)
                elif outcome == "failed":
                    self.failed = value
                else:
                    self.interrupted = True
                    stopping.signal()                    # the others stop too
            while following in done:
                yield done.pop(following)
                following += 1

    def _end(self) -> None:
        """Every worker ended: asked (no more jobs, or SIGTERM when stopped), then
        killed after ENDING_SECONDS."""
        for conn in self._conns:
            with contextlib.suppress(OSError):
                conn.send(None)
                conn.close()
        self._conns.clear()
        for process in self._processes:
            if (self.interrupted or self.timed_out) and process.is_alive():
                with contextlib.suppress(ProcessLookupError):
                    os.kill(process.pid, signal.SIGTERM)
        for process in self._processes:
            process.join(ENDING_SECONDS)
            if process.is_alive():
                process.kill()
                process.join()
        self._processes.clear()


def _serve(conn: Connection) -> None:
    """A worker: jobs from ``conn`` until there are no more; a stopping signal ends it at
    once (see the module's docstring)."""
    for sig in STOPPING:
        signal.signal(sig, _leave)
    _watch_parent()
    while True:
        try:
            task = conn.recv()
        except EOFError:
            return
        if task is None:                       # no more jobs
            return
        fn, item = task
        try:
            reply = ("done", fn(item))
        except Exception:
            reply = ("failed", traceback.format_exc())
        try:
            with StopSignals.held():            # a reply goes out whole or not at all
                conn.send(reply)
        except OSError:
            return                             # the parent is gone: nobody to tell


def _watch_parent() -> None:
    """Stop this worker as a signal would when its parent ends (killed outright: its
    signals never came)."""
    parent = multiprocessing.parent_process()
    if parent is None:
        return

    def watch() -> None:
        wait([parent.sentinel])
        os.kill(os.getpid(), signal.SIGTERM)

    threading.Thread(target=watch, name="parent-watch", daemon=True).start()


def workers(jobs: int, seconds: float | None = None) -> Workers:
    """A pool whose ``map`` runs ``jobs`` at a time (in order of the items), for at most
    ``seconds`` when given."""
    return Workers(jobs, seconds)
