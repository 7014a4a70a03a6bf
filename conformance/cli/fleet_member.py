"""One member of a fleet (cli/fleet.py): ``python -m conformance.cli.fleet_member JOB``
runs the one target of JOB (the fleet's parsed options as JSON) as a single run would.

SIGINT (what the fleet passes on), SIGTERM and SIGHUP stop it alike. Its standard input
is a pipe the fleet holds: when it ends while the member runs, the fleet is gone (killed
outright, its signals never sent), and the member stops as if signalled — its unit gets
`H`, its report is written — instead of running on with nobody reading its output."""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import signal
import stat
import sys
import threading
from pathlib import Path

from conformance.cli.usage import INTERRUPTED
from conformance.link.signals import StopSignals


def _fleet_gone() -> None:
    """Wait for the fleet's pipe to end, then stop this member as a closed terminal would
    (its output, read by nobody now, goes nowhere)."""
    # os.read, not sys.stdin: a daemon thread inside a buffered read at exit is fatal
    with contextlib.suppress(OSError):
        while os.read(0, 4096):
            pass
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, sys.stdout.fileno())
    os.dup2(devnull, sys.stderr.fileno())
    os.kill(os.getpid(), signal.SIGHUP)


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    with StopSignals.alike():
        try:
            job = json.loads(Path(argv[0]).read_text(encoding="utf-8"))
            if stat.S_ISFIFO(os.fstat(0).st_mode):          # the fleet's pipe
                threading.Thread(target=_fleet_gone, name="fleet-gone", daemon=True).start()
            from conformance.cli.run import execute
            return execute(argparse.Namespace(**job["args"]), job["argv"])
        except KeyboardInterrupt:
            # only before the run began: a run interrupted halts its unit, reports, returns
            print("interrupted before the run began", file=sys.stderr)
            return INTERRUPTED


if __name__ == "__main__":
    sys.exit(main())
