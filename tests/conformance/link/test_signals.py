"""Stop signals held back around a write: none lands inside the block, each is delivered
after (a flag while the run's own handler is installed, a handler swap otherwise)."""

from __future__ import annotations

import os
import select
import signal
import subprocess
import threading
from pathlib import Path

import pytest

from conformance.link.signals import STOPPING, StopSignals


def test_a_signal_taken_by_another_thread_still_waits_for_the_end_of_the_block():
    """A process-directed signal may be taken by any thread that does not block it; the
    handler must still not run inside the held block, and must run once after it."""
    seen: list[str] = []
    previous = signal.signal(signal.SIGHUP, lambda *_: seen.append("handler"))
    release = threading.Event()
    other = threading.Thread(target=release.wait)    # a thread that does not block signals
    other.start()
    woken, wake = os.pipe()
    os.set_blocking(wake, False)
    old_wakeup = signal.set_wakeup_fd(wake)      # the C-level handler writes here when it runs
    try:
        with StopSignals.held():
            signal.pthread_kill(other.ident, signal.SIGHUP)
            assert select.select([woken], [], [], 10)[0], "the signal never arrived"
            for _ in range(1000):                 # loop checks, where Python runs handlers
                pass
            seen.append("block ends")
        for _ in range(1000):
            pass
    finally:
        signal.set_wakeup_fd(old_wakeup)
        os.close(woken)
        os.close(wake)
        release.set()
        other.join()
        signal.signal(signal.SIGHUP, previous)
    assert seen == ["block ends", "handler"]


def test_a_signal_to_a_default_handler_is_raised_after_the_block():
    with_default = signal.getsignal(signal.SIGINT)
    assert with_default is signal.default_int_handler
    reached = []
    try:
        with StopSignals.held():
            os.kill(os.getpid(), signal.SIGINT)
            for _ in range(10_000):
                pass
            reached.append("end of block")
        for _ in range(10_000):
            pass
    except KeyboardInterrupt:
        reached.append("interrupted")
    assert reached == ["end of block", "interrupted"]


def test_a_signal_raised_inside_the_block_still_waits_for_its_end():
    # starting a program (fork_exec) lets Python run a handler right after: the handler
    # that runs then must not raise where the program's Popen would be lost
    reached = []
    try:
        with StopSignals.held():
            signal.raise_signal(signal.SIGINT)
            reached.append("end of block")
    except KeyboardInterrupt:
        reached.append("interrupted")
    assert reached == ["end of block", "interrupted"]


def test_a_program_started_inside_the_block_takes_the_stopping_signals():
    """No signal mask is inherited: a fleet's member, a host program, a simulator started
    with the signals held still stops on SIGINT, SIGTERM and SIGHUP."""
    with StopSignals.held():
        program = subprocess.Popen(["sleep", "60"])
    try:
        status = Path(f"/proc/{program.pid}/status")
        if status.exists():
            blocked = int(next(line.split()[1] for line in status.read_text().splitlines()
                               if line.startswith("SigBlk:")), 16)
            assert not blocked & sum(1 << (s - 1) for s in STOPPING)
        program.send_signal(signal.SIGTERM)
        assert program.wait(10) == -signal.SIGTERM
    finally:
        program.kill()
        program.wait()


def test_a_write_under_the_runs_own_handler_swaps_no_handler(monkeypatch):
    """Per write, only a flag: a signal that comes during the write is counted once it is
    over (the frame went out before the signal), and no handler is swapped."""
    stops = StopSignals()
    with stops.catching():
        real, swapped = signal.signal, []
        monkeypatch.setattr(signal, "signal", lambda *a: (swapped.append(a), real(*a))[1])
        for n in range(StopSignals.HARD - 1):
            with stops.writing():
                assert stops.bars() == (n > 0)
                signal.raise_signal(signal.SIGTERM)
                for _ in range(1000):             # loop checks, where Python runs handlers
                    pass
                assert stops.count == n           # not yet: the bytes go out first
            assert stops.count == n + 1 and stops.bars()    # the next frame is an H
        with pytest.raises(KeyboardInterrupt), stops.writing():
            signal.raise_signal(signal.SIGTERM)   # the last: at the end of the write
        monkeypatch.undo()
        assert swapped == []


def test_a_write_under_another_handler_holds_the_signals_back():
    stops = StopSignals()
    reached = []
    try:
        with stops.writing():
            signal.raise_signal(signal.SIGINT)
            reached.append("end of block")
    except KeyboardInterrupt:
        reached.append("interrupted")
    assert reached == ["end of block", "interrupted"]
