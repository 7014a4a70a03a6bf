"""Why results were not tested, in a few words for a run's last line: the reasons of
COULD-NOT-TEST and MISSING results, read from their notes by the table in
untested.toml, counted and worst-first."""

from __future__ import annotations

import re
import tomllib
from collections.abc import Iterable
from functools import cache
from importlib import resources
from typing import Protocol

#: the phrase of a result no pattern of the table matches
OTHER = "for another reason (each case's note says which)"
#: the phrase of what a profile does not have: the one reason a run that did not test
#: it still PASSED (untested.toml says it so)
NOT_IN_PROFILE = "not in the profile"


class Noted(Protocol):
    verdict: str
    notes: list[str]


@cache
def reasons() -> tuple[tuple[re.Pattern[str], str], ...]:
    """(pattern, phrase) pairs of untested.toml, in the file's order."""
    text = resources.files("conformance.verdicts").joinpath("untested.toml").read_text("utf-8")
    return tuple((re.compile(r["pattern"], re.IGNORECASE), r["phrase"])
                 for r in tomllib.loads(text)["reason"])


def why(notes: Iterable[str]) -> str:
    """The short phrase for a result with ``notes``: the first pattern of the table
    found in any note."""
    notes = list(notes)
    for pattern, phrase in reasons():
        if any(pattern.search(n) for n in notes):
            return phrase
    return OTHER


def grouped(results: Iterable[Noted], untested: tuple[str, ...]) -> dict[str, int]:
    """How many results of a verdict in ``untested`` there are per phrase, the most
    frequent first."""
    counts: dict[str, int] = {}
    for r in results:
        if r.verdict in untested:
            phrase = why(r.notes)
            counts[phrase] = counts.get(phrase, 0) + 1
    return dict(sorted(counts.items(), key=lambda kv: (-kv[1], kv[0])))
