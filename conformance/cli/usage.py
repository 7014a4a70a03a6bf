"""What every subcommand does with a mistake on its command line: one line on standard
error, exit status 2, nothing sent. The parser that raises instead of printing its usage,
and the value types that refuse nonsense (a NaN, a baud rate of 0, a run id that climbs
out of --report-dir) before the run opens a port."""

from __future__ import annotations

import argparse
import math
import re
import tempfile
import textwrap
from collections.abc import Sequence
from pathlib import Path
from typing import Any, NoReturn

from conformance.verdicts.verdict import INCOMPLETE, PASSED

#: the longest --seconds / --host-timeout taken: a day (a typo of many zeros is a mistake)
LONGEST_SECONDS = 86400.0
_RUN_ID = re.compile(r"[A-Za-z0-9][A-Za-z0-9._-]{0,99}")


#: the exit status of a job that a stopping signal (Ctrl-C, SIGTERM, SIGHUP) cut short:
#: a shell's 128 + SIGINT, whichever of them came (the job handles them alike)
INTERRUPTED = 130


#: the exit status of a run that FAILed nothing yet did not test what it was asked to
#: (INCOMPLETE: motion declined, a rig missing...), unless --accept-incomplete
INCOMPLETE_STATUS = 3


def exit_status(passed: bool, interrupted: bool = False) -> int:
    """0 for a job that passed, 1 for one that did not, INTERRUPTED for one a signal
    stopped (whatever it had found by then: the reports say)."""
    return INTERRUPTED if interrupted else 0 if passed else 1


def verdict_status(verdict: str, *, lost: bool = False, interrupted: bool = False,
                   accept_incomplete: bool = False) -> int:
    """The exit status of a job whose last line says ``verdict``: 0 PASSED (and
    INCOMPLETE when ``accept_incomplete``), INCOMPLETE_STATUS for INCOMPLETE, 1 FAILED
    or a report ``lost``, INTERRUPTED for a job a signal stopped."""
    if interrupted:
        return INTERRUPTED
    if lost or verdict not in (PASSED, INCOMPLETE):
        return 1
    return INCOMPLETE_STATUS if verdict == INCOMPLETE and not accept_incomplete else 0


class UsageError(Exception):
    """A mistake on the command line: one line, exit status 2, nothing sent."""


#: the targets every subcommand that talks to a unit takes, for its --help
TARGET_FORMS = """\
targets (--target):
  emu:PROFILE[?mutant=NAME]         the embedded emulator, in virtual time (emu:all: every
                                    profile)
  serial:PATH[?baud=N&address=A]    a unit on a serial port or pseudo-terminal
  tcp:HOST:PORT                     a unit or a simulator on a raw TCP port
  exec:COMMAND                      a simulator the suite starts: it prints its port first,
                                    its standard input is the test rig (docs/rig.md)"""


def summary(doc: str | None) -> str:
    """A module docstring's first paragraph as one text: whole sentences for --help."""
    first = (doc or "").strip().split("\n\n")[0]
    return textwrap.fill(" ".join(first.split()), 88)


def add_loudness(ap: argparse.ArgumentParser | argparse._ArgumentGroup, verbose: str) -> None:
    """``-q`` (the recap and the verdict's line only) or ``-v`` (``verbose``: what every
    line is), one or the other, and ``--color``, alike on every subcommand."""
    loud = ap.add_mutually_exclusive_group()
    loud.add_argument("-q", "--quiet", action="store_true",
                      help="print only the end: what failed, where the reports are and "
                           "the verdict's line")
    loud.add_argument("-v", "--verbose", action="store_true", help=verbose)
    ap.add_argument("--color", "--colour", choices=("auto", "always", "never"),
                    default="auto", help="colour the verdicts: auto (a terminal without "
                    "NO_COLOR set), always or never (default auto)")


#: --seed's help, the same wherever a job draws at random
SEED_HELP = ("the seed of what the job draws at random: the same N draws the same again "
             "(default: a fresh one, printed and recorded in the reports)")


def job_options(verbose: str, *, reports: bool = True, seed: str | None = SEED_HELP,
                jobs: str | None = None, jobs_default: int = 1, cases: bool = False,
                time_limit: str | None = None) -> argparse.ArgumentParser:
    """The options the subcommands share, with the same names, defaults and help
    everywhere: one parent parser (``Parser(parents=[job_options(...)])``), of which each
    job takes the parts that mean something to it. Always ``-q``/``-v`` (``verbose``: what
    -v shows on this job) and ``--color``; ``reports``: --report-dir, --run-id,
    --no-reports, --junitxml and --accept-incomplete; ``seed``: what its --seed seeds
    (None: a job that draws nothing at random has none); ``jobs``: what -j/--jobs runs
    side by side (``jobs_default`` of them); ``cases``: --cases and --exclude, for a job
    that runs the catalogue's cases; ``time_limit``: what --seconds S does."""
    ap = argparse.ArgumentParser(add_help=False)
    out = ap.add_argument_group("reports and output")
    if reports:
        out.add_argument("--report-dir", default="reports",
                         help="where reports/<run id>/ go (default %(default)s)")
        out.add_argument("--run-id", type=run_id, metavar="NAME",
                         help="the report folder's name (default: date, time and a random "
                              "tag)")
        out.add_argument("--no-reports", action="store_true",
                         help="write no report folder (--junitxml still writes its file)")
        out.add_argument("--junitxml", metavar="PATH", help="also write the JUnit XML at PATH")
        out.add_argument("--accept-incomplete", action="store_true",
                         help=f"exit 0 for a run that ends INCOMPLETE (nothing failed, yet "
                              f"some of it was not tested: motion declined, no rig, the time "
                              f"limit...); otherwise its exit status is {INCOMPLETE_STATUS}")
    add_loudness(out, verbose)
    job = ap.add_argument_group("what runs")
    if jobs is not None:
        job.add_argument("--jobs", "-j", type=positive, default=jobs_default, metavar="N",
                         help=f"{jobs} (default %(default)s)")
    if cases:
        job.add_argument("--cases", action="append", default=[], metavar="GLOB",
                         help="run only cases whose ID matches (repeatable)")
        job.add_argument("--exclude", action="append", default=[], metavar="GLOB",
                         help="leave out cases whose ID matches (repeatable; after --cases)")
    if time_limit is not None:
        job.add_argument("--seconds", type=seconds, metavar="S", help=time_limit)
    if seed is not None:
        job.add_argument("--seed", type=int, metavar="N", help=seed)
    return ap


#: --seconds' help on a job that ends early when its time is up
TIME_LIMIT_HELP = ("stop after S seconds: what finished by then is reported, the rest not "
                   "tested (the job ends INCOMPLETE unless something failed)")


class _Version(argparse.Action):
    """``--version``: the version, the C stepper core's state and the Python, read only
    when asked (the emulator is not imported otherwise)."""

    def __init__(self, option_strings: Sequence[str], dest: str = argparse.SUPPRESS,
                 **kwargs: Any) -> None:
        super().__init__(option_strings, dest, nargs=0, default=argparse.SUPPRESS, **kwargs)

    def __call__(self, parser: argparse.ArgumentParser, *_: Any) -> None:
        from conformance.targets.emu import version_text
        print(version_text(parser.prog))
        parser.exit(0)


class Parser(argparse.ArgumentParser):
    """argparse without the usage dump: its errors become one UsageError line. Every
    parser has ``--version``; ``examples`` (and ``targets``: the target forms) close
    its --help."""

    def __init__(self, *args: Any, examples: Sequence[str] = (), targets: bool = False,
                 **kwargs: Any) -> None:
        tail = ([TARGET_FORMS] if targets else []) + (
            [kwargs["epilog"]] if kwargs.get("epilog") else []) + (
            ["examples:\n" + "\n".join(f"  {e}" for e in examples)] if examples else [])
        if tail:
            kwargs["epilog"] = "\n\n".join(tail)
        kwargs.setdefault("formatter_class", argparse.RawDescriptionHelpFormatter)
        super().__init__(*args, **kwargs)
        self.add_argument("--version", action=_Version,
                          help="print the version, the C stepper core's state and the "
                               "Python, then exit")

    def error(self, message: str) -> NoReturn:
        raise UsageError(message)


def chosen_cases(args: argparse.Namespace) -> list:
    """The cases ``--cases``/``--exclude`` select (all where neither is given); a
    UsageError where they select none."""
    from conformance.run.selection import select  # the catalogue loads only when asked
    cases = select(args.cases or None, args.exclude or None)
    if not cases:
        raise UsageError("no case matches " + " ".join(
            [f"--cases {g!r}" for g in args.cases] + [f"--exclude {g!r}" for g in args.exclude]))
    return cases


def one_line(err: BaseException) -> str:
    """An error as one line for the user (a KeyError's text without its quotes)."""
    text = err.args[0] if err.args and isinstance(err.args[0], str) else str(err)
    return (text.splitlines() or [type(err).__name__])[0]


def seconds(text: str) -> float:
    """A duration: finite, more than 0, at most a day."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number of seconds: {text!r}") from None
    if not math.isfinite(value) or not 0 < value <= LONGEST_SECONDS:
        raise argparse.ArgumentTypeError(
            f"{text!r}: give a number of seconds above 0 and at most {LONGEST_SECONDS:g}")
    return value


def positive(text: str) -> int:
    """A whole number of 1 or more (a baud rate, a count of jobs or examples)."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a whole number: {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"{text!r}: give 1 or more")
    return value


def run_id(text: str) -> str:
    """A run's name: one folder inside --report-dir (letters, digits, '.', '_', '-')."""
    if not _RUN_ID.fullmatch(text) or ".." in text:
        raise argparse.ArgumentTypeError(
            f"{text!r}: a run id is one folder name (letters, digits, '.', '_', '-'; "
            "no '/' and no '..')")
    return text


def writable_folder(folder: str | Path, what: str = "reports") -> Path:
    """``folder``, created if need be, once a file could be written in it."""
    folder = Path(folder)
    if folder.exists() and not folder.is_dir():      # mkdir would say "File exists"
        raise UsageError(f"cannot write {what} to {folder}: it is a file, not a folder")
    try:
        folder.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=folder):
            pass
    except OSError as err:
        raise UsageError(f"cannot write {what} to {folder}: {err.strerror or err}") from None
    return folder
