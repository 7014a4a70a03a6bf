"""Why a case got its verdict, said one way wherever a verdict is read (the console, the
recap, every report, pytest): the deciding check — the failed check that made the
verdict, not merely the first one to fail — with the ID and tag of the rule it judges,
what the unit did and what the rule wants, and the rule's own sentence with its source;
for a verdict no check made (ERROR, COULD-NOT-TEST, MISSING) the note that says why."""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

from conformance.verdicts.quoting import quoted
from conformance.verdicts.verdict import CHECK_TAGS, FAIL, INFO, NON_STRICT, ORDER, grade
from gve_fixtures.rules import load_rules

#: the verdicts a failed check gives (the others come from what stopped the case)
GRADED = (FAIL, NON_STRICT, INFO)


class Judged(Protocol):
    id: str
    verdict: str
    rule: str          # the case's own requirement (its first rule's text)
    source: str
    checks: list[dict]
    notes: list[str]


def _severity(check: dict) -> int:
    """How bad a failed check is on any target: graded by its tag as a third-party
    target is (a manual's rule before a decision), so that on a target graded strictly,
    where a [D] point FAILs too, a broken [M] rule still decides."""
    tag = check.get("tag", "")
    return ORDER.index(grade(tag, False)) if tag in CHECK_TAGS else 0


def deciding_check(checks: Sequence[dict], verdict: str) -> dict | None:
    """The failed check that made ``verdict``: the worst-graded one, the first of those;
    None when no check made it (an ERROR, a case that could not be tested)."""
    if verdict not in GRADED:
        return None
    return min((c for c in checks if not c["ok"]), key=_severity, default=None)


@dataclass(frozen=True)
class Reason:
    """Why one case run got its verdict."""

    verdict: str
    what: str                 # what was checked (or why nothing was judged)
    rule_id: str = ""         # the rule the deciding check judges ("" when it names none)
    tag: str = ""             # the tag that graded it (M, M-ex, D, D-info, always)
    observed: str = ""
    expected: str = ""
    rule: str = ""            # the rule's sentence (fixtures/rules.toml "text")
    source: str = ""          # where that sentence comes from (a manual's section)

    @property
    def checked(self) -> bool:
        """Whether a check made the verdict (else ``what`` says why there was none)."""
        return bool(self.tag)

    def seen(self) -> str:
        """``observed "code 4", expected "code 5"`` (empty when the check kept neither)."""
        if not (self.observed or self.expected):
            return ""
        return f"observed {quoted(self.observed)}, expected {quoted(self.expected)}"

    def head(self) -> str:
        """``1.profile.dollar-range [M]``: the rule and its tag (the tag alone when the
        check names no rule)."""
        if not self.checked:
            return ""
        return f"{self.rule_id} [{self.tag}]" if self.rule_id else f"[{self.tag}]"

    def line(self) -> str:
        """One line a person can act on: ``1.profile.dollar-range [M] $0 → 5: observed
        "code 4", expected "code 5"``."""
        seen = self.seen()
        return " ".join(p for p in (self.head(), self.what + (f": {seen}" if seen else ""))
                        if p)

    def cites(self) -> str:
        """The rule's sentence and its source as plain text (:func:`plain`): ``$ takes
        1..65535 ... (M54 $; M84 12.5.3)``."""
        if not self.rule:
            return ""
        return plain(f"{self.rule} ({self.source})" if self.source else self.rule)


#: the Markdown the rules' sentences are written in (fixtures/rules.toml: docs/spec.md is
#: made of them): code spans and bold
_MARKUP = re.compile(r"`([^`]+)`|\*\*([^*]+)\*\*")


def plain(text: str) -> str:
    """A rule's sentence (or a case's, or a source) for a console, a log or JUnit: its
    Markdown code spans and bold as their text (``!0H`` for `` `!0H` ``), no markup shown.
    The HTML report sets them as HTML instead (reports/text.py)."""
    return _MARKUP.sub(lambda m: m.group(1) or m.group(2), text)


def _why_not_judged(notes: Sequence[str]) -> str:
    """A verdict no check made: the first note, its first and last lines (a traceback's
    head and the exception)."""
    if not notes:
        return "no check failed and no note says why"
    lines = [line.strip() for line in notes[0].strip().splitlines() if line.strip()]
    if len(lines) <= 2:
        return " ".join(lines)
    return f"{lines[0]} … {lines[-1]}"


def reason(r: Judged) -> Reason:
    """Why ``r`` got its verdict (see the module's text)."""
    c = deciding_check(r.checks, r.verdict)
    if c is None:
        return Reason(r.verdict, _why_not_judged(r.notes))
    rule_id = c.get("rule") or ""
    known = load_rules().get(rule_id)
    what = c["what"].removeprefix(f"{r.id}: ")       # every line names the case already
    return Reason(r.verdict, what, rule_id if known else "", c.get("tag", ""),
                  c.get("observed", ""), c.get("expected", ""),
                  known.text if known else r.rule, known.source if known else r.source)
