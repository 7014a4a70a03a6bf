"""What failed, first: per case that did not pass (FAIL, ERROR, NON-STRICT) the check that
gave it its verdict — what was checked, what the unit did, what the spec wants and the
rule — for the list at the top of the HTML page. A case failing the same way on several
profiles is one entry naming each of them."""

from __future__ import annotations

from dataclasses import dataclass, field

from conformance.runner import CaseResult, RunResult
from conformance.verdict import ERROR, FAIL, NON_STRICT, ORDER, grade
from gve_fixtures.profile import load_profile
from gve_fixtures.rules import load_rules

#: the verdicts the list shows, worst first
LISTED = (ERROR, FAIL, NON_STRICT)


@dataclass
class Failure:
    """One failing case (on one or more profiles) and why."""

    id: str
    verdict: str
    what: str
    observed: str = ""
    expected: str = ""
    rule_id: str = ""
    rule: str = ""                    # the rule's text
    runs: list[CaseResult] = field(default_factory=list)   # the case's runs it stands for


def _implements_decisions(profile: str) -> bool:
    try:
        return load_profile(profile).implements_decisions
    except (LookupError, ValueError, OSError):
        return True


def deciding_check(r: CaseResult) -> dict | None:
    """The first failed check graded as the case's verdict (else its first failed one)."""
    failed = r.failed_checks
    decisions = _implements_decisions(r.profile)
    for c in failed:
        try:
            if grade(c["tag"], decisions) == r.verdict:
                return c
        except ValueError:
            continue
    return failed[0] if failed else None


def _why_not_run(r: CaseResult) -> str:
    """An ERROR without a failed check: the first note, its first and last lines (a
    traceback's head and the exception)."""
    if not r.notes:
        return "the case ended without a failed check and without a note"
    lines = [line for line in r.notes[0].strip().splitlines() if line.strip()]
    if len(lines) <= 2:
        return " ".join(lines)
    return f"{lines[0]} … {lines[-1].strip()}"


def failure_of(r: CaseResult) -> Failure:
    c = deciding_check(r)
    if c is None:
        return Failure(r.id, r.verdict, _why_not_run(r), rule=r.rule, runs=[r])
    rule_id = c.get("rule") or ""
    known = load_rules().get(rule_id) if rule_id else None
    what = c["what"].removeprefix(f"{r.id}: ")          # the list names the case already
    return Failure(r.id, r.verdict, what, c["observed"], c["expected"], rule_id,
                   known.text if known else r.rule, [r])


def failures(run: RunResult) -> list[Failure]:
    """The failing cases, worst verdict first, then in case order; the same case failing
    the same way on several profiles once."""
    out: dict[tuple, Failure] = {}
    for r in run.results:
        if r.verdict not in LISTED:
            continue
        f = failure_of(r)
        key = (f.id, f.verdict, f.what, f.observed, f.expected)
        if key in out:
            out[key].runs.append(r)
        else:
            out[key] = f
    return sorted(out.values(), key=lambda f: (ORDER.index(f.verdict), f.id))
