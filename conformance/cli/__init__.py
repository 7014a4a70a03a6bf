"""`gve-conformance` / `python -m conformance`: one program, several jobs.

    gve-conformance [OPTIONS]              run the suite against targets (cli/run.py)
    gve-conformance SUBCOMMAND [OPTIONS]   one of SUBCOMMANDS below

Each subcommand is one module of this package with ``main(argv) -> int`` and a parser of
its own; it is imported only when named, so the default run starts no more than it
needs (not argparse subparsers, which would import every job to build its parser, and
which cannot leave the subcommand out for the default run: docs/decisions.md).
"""

from __future__ import annotations

import importlib
import sys

from conformance.cli.commands import SUBCOMMANDS
from conformance.cli.usage import INTERRUPTED
from conformance.link.signals import StopSignals


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else list(argv)
    # SIGINT, SIGTERM and SIGHUP alike; a job that was stopped before its own handling
    # began (or after it ended) still ends with one line, not a traceback
    with StopSignals.alike():
        try:
            if args and args[0] in SUBCOMMANDS:
                module = importlib.import_module(SUBCOMMANDS[args[0]][0])
                return module.main(args[1:])
            from conformance.cli import run
            return run.main(args)
        except KeyboardInterrupt:
            print("gve-conformance: interrupted by a signal", file=sys.stderr, flush=True)
            return INTERRUPTED
