"""The subcommands of `gve-conformance`: which module runs each, and the one sentence
its top-level --help shows."""

from __future__ import annotations

import textwrap

#: subcommand -> (module, one whole sentence for the top-level --help)
SUBCOMMANDS: dict[str, tuple[str, str]] = {
    "run": ("conformance.cli.run", "Run the suite against targets and write the reports "
            "(what `gve-conformance` with no subcommand does)."),
    "ports": ("conformance.cli.ports", "List the serial ports of this machine, to find the "
              "one the unit is on."),
    "diff": ("conformance.cli.diff", "Differential fuzzing: send the same drawn sequences to "
             "the target and the emulator, and shrink each disagreement to a transcript."),
    "replay": ("conformance.cli.replay", "Replay a transcript (one `diff` wrote, or any) on a "
               "target and the emulator alike, and say whether they still disagree."),
    "host": ("conformance.cli.host", "Certify a host program: the suite plays the unit and "
             "judges what the host sends."),
    "mutation": ("conformance.cli.mutation", "The mutation score: hunt every deliberate bug "
                 "of the emulator with the catalogue until a case FAILs it."),
    "fairness": ("conformance.cli.fairness", "The fairness score: run the catalogue against "
                 "every reading of what the manuals leave open; no case may FAIL one."),
    "corpus": ("conformance.cli.corpus", "The independent implementations gate: judge every "
               "unit and host of corpus/ (written from one manual alone) as a user would; "
               "every FAIL must be a documented departure."),
}


def subcommands_help() -> str:
    """The subcommands for the top-level --help, one sentence each."""
    width = max(map(len, SUBCOMMANDS)) + 4
    lines = ["subcommands (gve-conformance SUBCOMMAND --help for each):"]
    for name, (_, what) in SUBCOMMANDS.items():
        lines += textwrap.wrap(what, 88, initial_indent=f"  {name:{width - 2}}",
                               subsequent_indent=" " * width)
    return "\n".join(lines)
