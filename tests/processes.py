"""Helpers for the processes tests start."""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
import time


def stop(proc: subprocess.Popen, grace: float = 10.0) -> None:
    """End ``proc``: SIGTERM, then SIGKILL if it has not ended within ``grace`` seconds."""
    if proc.poll() is not None:
        return
    proc.terminate()
    try:
        proc.wait(grace)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait(grace)


def descendants(pid: int) -> list[int]:
    """Every process ``pid`` started, and theirs (Linux /proc; empty elsewhere)."""
    out, todo = [], [pid]
    while todo:
        parent = todo.pop()
        try:
            tasks = os.listdir(f"/proc/{parent}/task")
        except OSError:
            continue
        for task in tasks:
            try:
                with open(f"/proc/{parent}/task/{task}/children") as f:
                    found = [int(p) for p in f.read().split()]
            except OSError:
                continue
            out += found
            todo += found
    return out


def alive(pid: int) -> bool:
    """Whether ``pid`` still runs (a zombie has ended: only its parent has not reaped it)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


def wait_for(condition, deadline: float, what: str) -> None:
    """Poll ``condition()`` until it holds, up to ``deadline`` seconds (a deadline on a
    condition, not a sleep standing in for one)."""
    end = time.monotonic() + deadline
    while not condition():
        if time.monotonic() > end:
            raise TimeoutError(f"{what} within {deadline} s")
        time.sleep(0.02)


def signalled(argv: list[str], sig: int, *, ready, delay: float, group: bool = False,
              deadline: float = 60.0) -> tuple[int, str, list[int]]:
    """Run ``python -m conformance ARGV`` in a process group of its own; once
    ``ready(pid)`` holds, wait ``delay`` seconds more (the instant drawn), send ``sig`` to
    it (``group``: to its whole group, as a terminal's Ctrl-C does) and wait for its end:
    (exit status, its output, every process it had started by the signal)."""
    proc = subprocess.Popen([sys.executable, "-m", "conformance", *argv],
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            stdin=subprocess.DEVNULL, process_group=0)
    try:
        wait_for(lambda: ready(proc.pid) or proc.poll() is not None, deadline,
                 f"{argv[0]} did not get ready")
        time.sleep(delay)                      # the instant of the signal, drawn
        started = descendants(proc.pid)
        if group:
            os.killpg(proc.pid, sig)
        else:
            os.kill(proc.pid, sig)
        out, _ = proc.communicate(timeout=deadline)
        return proc.returncode, out.decode(errors="replace"), started
    finally:
        if proc.poll() is None:
            with contextlib.suppress(ProcessLookupError):
                os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
