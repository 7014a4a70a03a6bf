"""`gve-conformance` / `python -m conformance`: one program, several jobs.

    gve-conformance [OPTIONS]              run the suite against targets (cli/run.py)
    gve-conformance SUBCOMMAND [OPTIONS]   one of SUBCOMMANDS below

Each subcommand is one module of this package with ``main(argv) -> int``; it is imported
only when named, so the default run starts no more than it needs.
"""

from __future__ import annotations

import importlib
import sys

#: subcommand -> (module, one line for the help)
SUBCOMMANDS: dict[str, tuple[str, str]] = {
    "ports": ("conformance.cli.ports", "the serial ports of this machine, to find the unit's"),
    "mutation": ("conformance.cli.mutation", "the mutation score: every emulator mutant hunted "
                 "with the catalogue until a case FAILs it"),
    "fairness": ("conformance.cli.fairness", "the fairness score: the catalogue against "
                 "every reading the emulator can take of what the manuals leave open; no "
                 "case may FAIL one"),
    "host": ("conformance.cli.host", "certify a host program: the suite plays the unit"),
    "diff": ("conformance.cli.diff", "differential fuzzing: the target against the emulator, "
             "each disagreement shrunk to a transcript"),
    "replay": ("conformance.cli.replay", "replay a transcript on a target and the emulator "
               "alike: is the disagreement still there?"),
}


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else list(argv)
    if args and args[0] in SUBCOMMANDS:
        module = importlib.import_module(SUBCOMMANDS[args[0]][0])
        return module.main(args[1:])
    from conformance.cli import run
    return run.main(args)
