"""What failed, first: per case that did not pass (FAIL, ERROR, NON-STRICT) why — the
check that decided its verdict, what the unit did, what the rule wants, the rule and the
sentence it cites (conformance/verdicts/explain.py) — for the list at the top of the HTML page
and the recap at the end of a run. A case failing the same way on several profiles is
one entry naming each of them."""

from __future__ import annotations

from dataclasses import dataclass, field

from conformance.run.runner import CaseResult, RunResult
from conformance.verdicts.explain import Reason, reason
from conformance.verdicts.verdict import ERROR, FAIL, NON_STRICT, ORDER

#: the verdicts the list shows, worst first
LISTED = (ERROR, FAIL, NON_STRICT)


@dataclass
class Failure:
    """One failing case (on one or more profiles) and why."""

    id: str
    why: Reason
    runs: list[CaseResult] = field(default_factory=list)   # the case's runs it stands for

    @property
    def verdict(self) -> str:
        return self.why.verdict


def failures(run: RunResult, listed: tuple[str, ...] = LISTED) -> list[Failure]:
    """The cases whose verdict is one of ``listed``, worst verdict first, then in case
    order (section numbers in their order); the same case failing the same way on
    several profiles once."""
    out: dict[tuple[str, Reason], Failure] = {}
    for r in run.results:
        if r.verdict not in listed:
            continue
        why = reason(r)
        if (r.id, why) in out:
            out[r.id, why].runs.append(r)
        else:
            out[r.id, why] = Failure(r.id, why, [r])
    return sorted(out.values(), key=lambda f: (ORDER.index(f.verdict), natural(f.id)))


def natural(case_id: str) -> tuple[tuple[int, int | str], ...]:
    """A case ID's sort key, its numbers as numbers: 6.checksum before 11.golden, 10.2
    before 10.10."""
    return tuple((0, int(p)) if p.isdigit() else (1, p) for p in case_id.split("."))
