"""What failed, first: per case that did not pass (FAIL, ERROR, NON-STRICT) the check that
gave it its verdict — what was checked, what the unit did, what the spec wants and the
rule — for the list at the top of the HTML page. A case failing the same way on several
profiles is one entry naming each of them."""

from __future__ import annotations

from dataclasses import dataclass, field

from conformance.runner import CaseResult, RunResult
from conformance.verdict import ERROR, FAIL, NON_STRICT, ORDER, grade
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


def _graded(tag: str, strict: bool | None) -> str | None:
    """The verdict a failed check with ``tag`` gives (``strict`` None: not known, only a
    verdict every grading agrees on)."""
    try:
        if strict is None:
            lenient, strictly = grade(tag, False), grade(tag, True)
            return strictly if strictly == lenient else None
        return grade(tag, strict)
    except ValueError:
        return None


def deciding_check(r: CaseResult, strict: bool | None = None) -> dict | None:
    """The first failed check graded as the case's verdict (else its first failed one);
    ``strict``: how the case's target was graded (None: not known)."""
    failed = r.failed_checks
    for c in failed:
        if _graded(c["tag"], strict) == r.verdict:
            return c
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


def failure_of(r: CaseResult, strict: bool | None = None) -> Failure:
    c = deciding_check(r, strict)
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
    graded = {t.spec: {"strict": True, "by the tags": False}.get(t.graded)
              for t in run.meta.targets}
    out: dict[tuple, Failure] = {}
    for r in run.results:
        if r.verdict not in LISTED:
            continue
        f = failure_of(r, graded.get(r.target))
        key = (f.id, f.verdict, f.what, f.observed, f.expected)
        if key in out:
            out[key].runs.append(r)
        else:
            out[key] = f
    return sorted(out.values(), key=lambda f: (ORDER.index(f.verdict), f.id))
