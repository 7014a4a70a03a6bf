"""What every subcommand does with a mistake on its command line: one line on standard
error, exit status 2, nothing sent. The parser that raises instead of printing its usage,
and the value types that refuse nonsense (a NaN, a baud rate of 0, a run id that climbs
out of --report-dir) before the run opens a port."""

from __future__ import annotations

import argparse
import math
import re
import tempfile
from pathlib import Path
from typing import NoReturn

#: the longest --seconds / --host-timeout taken: a day (a typo of many zeros is a mistake)
LONGEST_SECONDS = 86400.0
_RUN_ID = re.compile(r"[A-Za-z0-9][A-Za-z0-9._-]{0,99}")


class UsageError(Exception):
    """A mistake on the command line: one line, exit status 2, nothing sent."""


class Parser(argparse.ArgumentParser):
    """argparse without the usage dump: its errors become one UsageError line."""

    def error(self, message: str) -> NoReturn:
        raise UsageError(message)


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
    try:
        folder.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=folder):
            pass
    except OSError as err:
        raise UsageError(f"cannot write {what} to {folder}: {err.strerror or err}") from None
    return folder
