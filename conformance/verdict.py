"""Verdicts and their grading from the spec's tags (docs/suite.md, spec preamble)."""

from __future__ import annotations

PASS = "PASS"
NON_STRICT = "NON-STRICT"
FAIL = "FAIL"
INFO = "INFO"
MISSING = "MISSING"
COULD_NOT_TEST = "COULD-NOT-TEST"
ERROR = "ERROR"

#: worst first: the verdict of a case is the worst of its checks
ORDER = (ERROR, FAIL, NON_STRICT, INFO, COULD_NOT_TEST, MISSING, PASS)
TAGS = ("M", "M-ex", "D", "D-info", "always")


def grade(tag: str, strict: bool) -> str:
    """The verdict of one failed check carrying ``tag`` on a target graded ``strict``ly
    (the reference emulator, or a target run with --strict) or by the tags alone."""
    if tag in ("M", "M-ex", "always"):
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
#: verdicts that judged the target (the others say why it could not be judged)
JUDGED = (PASS, NON_STRICT, INFO)


def overall(verdicts: list[str], interrupted: bool = False, problems: list[str] = ()
            ) -> tuple[str, str]:
    """PASSED or FAILED for a run's case verdicts, with the reason in a few words. A run
    that judged nothing has not passed: a broken or silent target never earns a PASS;
    nor has one that left something of a unit unrestored (``problems``)."""
    bad = [v for v in ORDER if failing(v) and v in verdicts]
    if bad:
        return FAILED, " and ".join(f"{verdicts.count(v)} {v}" for v in bad)
    if problems:
        return FAILED, f"{len(problems)} problem(s) restoring the unit: {problems[0]}"
    if interrupted:
        return FAILED, "interrupted before every case had run"
    if not any(v in JUDGED for v in verdicts):
        return FAILED, "no case could judge the target"
    return PASSED, "no case failed"
