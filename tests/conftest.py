"""What every test shares: the Ctrl-C tests send SIGINT to the programs they start, and
a program started with SIGINT ignored (as a shell starts a background job, and passes it
on) never sees it. Caught here, SIGINT goes back to its default in every child."""

import os
import signal

if signal.getsignal(signal.SIGINT) == signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)


def pytest_xdist_auto_num_workers(config) -> int | None:
    """`-n auto`: two workers per core. Half the default run's time is real time spent
    waiting (a unit on a pseudo-terminal restarting, answering at the line's pace, a
    program starting), with the core idle; a second worker per core fills it.
    PYTEST_XDIST_AUTO_NUM_WORKERS still decides where it is set."""
    if os.environ.get("PYTEST_XDIST_AUTO_NUM_WORKERS"):
        return None                      # pytest-xdist's own reading of it
    cores = (len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity")
             else os.cpu_count() or 1)
    return 2 * cores
