"""The worker pool of `mutation`, `fairness` and `corpus`: SIGINT, SIGTERM and SIGHUP alike — to
the main process, to one worker alone, or the main process killed outright — end the
map with the results so far, every worker ended, nothing raised past the pool."""

from __future__ import annotations

import multiprocessing
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from conformance.cli.pool import WorkerFailed, workers
from conformance.link.signals import STOPPING

#: seconds a job "works" when it is not the first: long enough to be stopped in
LONG = 60.0


def job(n: int) -> int:
    """Returns at once for 0, else runs until stopped (or LONG seconds pass)."""
    end = time.monotonic() + (0 if n == 0 else LONG)
    while time.monotonic() < end:
        pass
    return n


def pid_of_worker(n: int) -> int:
    return os.getpid()


def failing(n: int) -> int:
    raise ValueError(f"job {n} broke")


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    # a zombie is no worker: it has ended, its parent has not reaped it yet
    status = f"/proc/{pid}/stat"
    return not (os.path.exists(status) and open(status).read().split()[2] == "Z")


def _children(before: frozenset[int] = frozenset()) -> list[int]:
    """This process's children not among ``before`` (processes other tests of this
    worker left to end on their own are not the pool's)."""
    task = Path(f"/proc/{os.getpid()}/task/{os.getpid()}/children")
    pids = [int(p) for p in task.read_text().split()] if task.exists() else []
    return [p for p in pids if p not in before]


@pytest.mark.parametrize("sig", STOPPING, ids=lambda s: signal.Signals(s).name)
def test_a_signal_to_this_process_stops_every_worker_and_ends_the_map(sig):
    got, started, before = [], time.monotonic(), frozenset(_children())
    with workers(2) as pool:
        for result in pool.map(job, [0, 1, 2, 3]):
            got.append(result)
            if result == 0:
                pids = _children(before)
                os.kill(os.getpid(), sig)
    assert got == [0] and pool.interrupted
    assert time.monotonic() - started < LONG / 2
    assert pids and not any(_alive(p) for p in pids)


def job_in(n: int) -> tuple[int, int]:
    """:func:`job`, and the worker that ran it."""
    return job(n), os.getpid()


def test_a_signal_to_one_worker_alone_stops_them_all():
    # the worker is the one that ran job 0, the pool's the multiprocessing children: a
    # process another test left starting meanwhile is no worker, and signalling it would
    # stop nothing
    before = {p.pid for p in multiprocessing.active_children()}
    with workers(2) as pool:
        for result, worker in pool.map(job_in, [0, 1, 2, 3]):
            if result == 0:
                pids = [p.pid for p in multiprocessing.active_children()
                        if p.pid not in before]
                assert worker in pids and len(pids) == 2
                os.kill(worker, signal.SIGTERM)
    assert pool.interrupted
    assert not any(_alive(p) for p in pids)


def test_without_a_signal_every_result_comes_in_order_and_the_workers_end():
    with workers(3) as pool:
        got = list(pool.map(pid_of_worker, range(9)))
    assert not pool.interrupted and len(got) == 9
    assert os.getpid() not in got and not any(_alive(p) for p in set(got))


#: per lane: its jobs under way now, and the most ever at once (the workers are forked:
#: they share these)
_UNDER_WAY = {lane: multiprocessing.Value("i", 0) for lane in ("wait", "work")}
_MOST = {lane: multiprocessing.Value("i", 0) for lane in ("wait", "work")}
_WORKED = multiprocessing.Event()


def laned(item: tuple[str, int]) -> tuple[str, int, bool]:
    """A `wait` job ends once a `work` job has run; a `work` job runs once two `wait`
    jobs are under way (False: what it waited for never came)."""
    lane, n = item
    with _UNDER_WAY[lane].get_lock():
        _UNDER_WAY[lane].value += 1
        _MOST[lane].value = max(_MOST[lane].value, _UNDER_WAY[lane].value)
    if lane == "work":
        end = time.monotonic() + LONG
        while _UNDER_WAY["wait"].value < 2 and time.monotonic() < end and not _WORKED.is_set():
            pass
        seen = _WORKED.is_set() or _UNDER_WAY["wait"].value >= 2
        _WORKED.set()
    else:
        seen = _WORKED.wait(LONG)
    with _UNDER_WAY[lane].get_lock():
        _UNDER_WAY[lane].value -= 1
    return lane, n, seen


def test_each_lane_runs_jobs_at_a_time_beside_the_others():
    """Jobs that wait on one that works, listed first: with a lane each, as many of each
    run at a time as the pool has jobs, side by side, and the results come in order."""
    items = [("wait", n) for n in range(3)] + [("work", n) for n in range(3)]
    with workers(2) as pool:
        got = list(pool.map(laned, items, lane=lambda item: item[0]))
    assert [(lane, n) for lane, n, _ in got] == items
    assert all(seen for *_, seen in got)
    assert _MOST["wait"].value == 2 and _MOST["work"].value <= 2


def test_a_job_that_raises_is_the_pools_error_once_the_workers_ended():
    before = frozenset(_children())
    with pytest.raises(WorkerFailed, match=r"job \d broke"), workers(2) as pool:
        list(pool.map(failing, [1, 2]))
    assert _children(before) == []


def test_one_job_runs_here_and_stops_alike():
    with workers(1) as pool:
        for result in pool.map(job, [0, 1]):
            if result == 0:
                os.kill(os.getpid(), signal.SIGHUP)
    assert pool.interrupted


def test_workers_whose_parent_is_killed_outright_end():
    """No orphan: the main process killed with SIGKILL (no handler runs) leaves no worker
    running."""
    code = ("import sys; sys.path.insert(0, %r)\n"
            "from tests.conformance.cli.test_pool import job\n"
            "from conformance.cli.pool import workers\n"
            "with workers(2) as pool:\n"
            "    for r in pool.map(job, [0, 1, 2]):\n"
            "        import os; print(open(f'/proc/{os.getpid()}/task/{os.getpid()}/children')"
            ".read(), flush=True)\n") % os.getcwd()
    main = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
    try:
        pids = [int(p) for p in main.stdout.readline().split()]
        assert pids
        main.kill()
        main.wait(10)
        end = time.monotonic() + 20           # a deadline for the condition, not a sleep
        while any(_alive(p) for p in pids) and time.monotonic() < end:
            time.sleep(0.05)
        assert not any(_alive(p) for p in pids)
    finally:
        main.kill()
        main.wait()
