"""Verdicts and their grading from the spec's tags (docs/suite.md, spec preamble)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol

from conformance.verdicts.untested import NOT_IN_PROFILE, grouped
from gve_fixtures import protocol

PASS = "PASS"
NON_STRICT = "NON-STRICT"
FAIL = "FAIL"
INFO = "INFO"
MISSING = "MISSING"
COULD_NOT_TEST = "COULD-NOT-TEST"
ERROR = "ERROR"



class CouldNotTest(Exception):
    """A precondition failed: the case cannot judge this target (its verdict is
    COULD-NOT-TEST). Raised below the cases too: by a target's rig, the session's way
    back, an operator who did not answer."""


#: worst first: the verdict of a case is the worst of its checks
ORDER = (ERROR, FAIL, NON_STRICT, INFO, COULD_NOT_TEST, MISSING, PASS)
#: the tag of a check no spec tag softens: a crash, a hang, two answers (spec preamble)
ALWAYS = "always"
#: the tags a check may carry: the spec's, and ALWAYS
CHECK_TAGS = (*protocol.TAGS, ALWAYS)
#: the rules the failures no tag softens break (spec preamble): bytes of the unit that
#: cannot be read as an answer, and a target that stopped answering
UNREADABLE, SILENT = "4.response.grammar", "2.link.answer-promptly"


def grade(tag: str, strict: bool) -> str:
    """The verdict of one failed check carrying ``tag`` on a target graded ``strict``ly
    (the reference emulator, or a target run with --strict) or by the tags alone."""
    if tag in ("M", "M-ex", ALWAYS):
        return FAIL
    if tag == "D":
        return FAIL if strict else NON_STRICT
    if tag == "D-info":
        return INFO
    raise ValueError(f"unknown tag {tag!r}")


def worst(verdicts: list[str]) -> str:
    if not verdicts:
        return PASS
    return min(verdicts, key=ORDER.index)


def failing(verdict: str) -> bool:
    """Whether the run's exit status must be non-zero."""
    return verdict in (FAIL, ERROR)


#: the run's overall verdict, the banner of its reports
PASSED = "PASSED"
FAILED = "FAILED"
#: nothing failed, yet the run did not test what it was asked to (motion declined, a
#: rig missing...): not a pass (docs/suite.md, "The last line")
INCOMPLETE = "INCOMPLETE"
#: verdicts that judged the target (the others say why it could not be judged)
JUDGED = (PASS, NON_STRICT, INFO)
#: verdicts of what was not tested (their reasons: conformance/verdicts/untested.toml)
UNTESTED = (COULD_NOT_TEST, MISSING)
#: the judged verdicts as the last line counts them: what failed, then what passed
LINE_ORDER = (ERROR, FAIL, PASS, NON_STRICT, INFO)


class Result(Protocol):
    verdict: str
    notes: list[str]


def counted(verdicts: Sequence[str], among: Sequence[str] = ORDER) -> str:
    """``120 PASS, 8 NON-STRICT``: the verdicts of ``among`` present, worst first."""
    return ", ".join(f"{verdicts.count(v)} {v}" for v in among if v in verdicts)


def not_tested(results: Sequence[Result], interrupted: bool = False) -> str:
    """``not tested: 12 of 149 (9 need a rig, 3 beyond the envelope)``, or
    ``everything tested`` (``interrupted``: the results are only what ran before it, so
    never "everything")."""
    groups = grouped(results, UNTESTED)
    if not groups:
        return (f"{len(results)} run before the interruption, nothing after it" if interrupted
                else f"everything tested ({len(results)})")
    n = sum(groups.values())
    return (f"not tested: {n} of {len(results)} ("
            + ", ".join(f"{k} {phrase}" for phrase, k in groups.items()) + ")")


def overall(results: Sequence[Result], interrupted: bool = False,
            problems: Sequence[str] = ()) -> tuple[str, str]:
    """PASSED, INCOMPLETE or FAILED for a run's results, with what was judged and what
    was not tested and why: ``INCOMPLETE``, ``120 PASS, 8 NON-STRICT; not tested: 12 of
    149 (9 need a rig, 3 beyond the envelope)``. FAILED when something FAILed or ERRed.
    A run that judged nothing has not passed: a broken or silent target never earns a
    PASS; nor has one that left something of a unit unrestored (``problems``) or was
    interrupted. INCOMPLETE when nothing failed yet a case was not tested for a reason
    other than its rule not being in the profile (motion declined, no rig...); else
    PASSED."""
    verdicts = [r.verdict for r in results]
    tested = counted(verdicts, LINE_ORDER) or "nothing judged"
    tail = f"{tested}; {not_tested(results, interrupted)}"
    if any(failing(v) for v in verdicts):
        return FAILED, tail
    if problems:
        return FAILED, (f"{len(problems)} problem(s) restoring the unit: {problems[0]}; "
                        + tail)
    if interrupted:
        return FAILED, f"interrupted before every case had run; {tail}"
    if not any(v in JUDGED for v in verdicts):
        return FAILED, f"no case could judge the target; {tail}"
    # MISSING is what the profile lacks, whatever its note says
    if any(phrase != NOT_IN_PROFILE for phrase in grouped(results, (COULD_NOT_TEST,))):
        return INCOMPLETE, tail
    return PASSED, tail


def last_line(results: Sequence[Result], interrupted: bool = False,
              problems: Sequence[str] = ()) -> str:
    """The last line of every command: ``PASSED — ...``, ``INCOMPLETE — ...`` or
    ``FAILED — ...``."""
    verdict, reason = overall(results, interrupted, problems)
    return f"{verdict} — {reason}"
