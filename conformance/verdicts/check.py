"""One check of a result: what was checked, whether it held, what the target did and
what the rule wants (both as text, as :func:`conformance.verdicts.quoting.as_text` keeps them),
the tag that grades a failure and the rule it judges. Every check of every result, a
case's, a known-state step's, a diff finding's, a host scenario's, is this record, and
:meth:`Check.to_dict` is the one place it becomes data: a result keeps its checks as
that data, which results.json, JUnit and the HTML page show."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Check:
    ok: bool
    what: str
    observed: str = ""
    expected: str = ""
    tag: str = ""
    rule: str = ""           # the rule ID of fixtures/rules.toml it judges

    def to_dict(self) -> dict[str, bool | str]:
        """The check as a result keeps it (and results.json writes it)."""
        return {"ok": self.ok, "what": self.what, "observed": self.observed,
                "expected": self.expected, "tag": self.tag, "rule": self.rule}
