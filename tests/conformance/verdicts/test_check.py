"""A check is one typed record, and results keep it, and results.json writes it, in one
form: the six fields every reader downstream (JUnit, the page, fairness, corpus, fleet
merges) reads by name."""

from __future__ import annotations

import dataclasses
import json

import pytest

from conformance.case.context import Case
from conformance.reports import write_reports
from conformance.reports.logs import compact_checks
from conformance.run.runner import RunResult, run_case
from conformance.targets import parse_target
from conformance.verdicts.check import Check
from conformance.verdicts.verdict import FAIL, PASS

#: the keys of a check in results.json: its readers depend on them, so they never change
KEYS = ["ok", "what", "observed", "expected", "tag", "rule"]


def test_a_check_becomes_data_with_the_results_json_keys_in_their_order():
    c = Check(False, "the answer", "8,D0", "0", "M", "5.code.ok")
    assert list(c.to_dict()) == KEYS
    assert c.to_dict() == {"ok": False, "what": "the answer", "observed": "8,D0",
                           "expected": "0", "tag": "M", "rule": "5.code.ok"}
    assert Check(**c.to_dict()) == c
    with pytest.raises(dataclasses.FrozenInstanceError):
        c.ok = True                                    # a verdict's evidence stays as taken


def test_a_case_s_checks_reach_results_json_as_that_record(tmp_path):
    def body(ctx):
        ctx.expect(True, "first", observed=b"0\r", expected="0", rule="5.code.ok")
        ctx.expect(False, "second", observed=None, expected="5", rule="5.code.ok")

    case = Case("99.toy.case", body, rule="toy", tag="M", source="test",
                rules=("10.3.st6.free", "5.code.ok"))
    r = run_case(case, parse_target("emu:GVE84-100"))
    assert r.verdict == FAIL
    assert [list(c) for c in r.checks] == [KEYS, KEYS]
    assert [Check(**c) for c in r.checks][1] == Check(False, "second", "", "5", "M",
                                                     "5.code.ok")
    folder = write_reports(RunResult("check-keys", [r], ["emu:GVE84-100"]), tmp_path)
    written = json.loads((folder / "results.json").read_text())["results"][0]["checks"]
    # a check's rule is left out only where it is the case's own (it is not, here)
    assert [list(c) for c in written] == [KEYS, KEYS]


def test_the_line_that_stands_for_a_passing_case_s_other_checks_is_a_check_too():
    checks = [Check(True, f"vector {i}", tag="M", rule="r").to_dict() for i in range(5)]
    first, more = compact_checks(checks, PASS)
    assert first == checks[0] and list(more) == KEYS and more["ok"] is True
    assert "4 more passed checks" in more["what"]
