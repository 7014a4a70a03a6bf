"""Cases name the rules they check; a check naming its rule is graded by that rule's tag
(fixtures/rules.toml), and a motion trace is kept with the result."""

from __future__ import annotations

import dataclasses
import json

import pytest

from conformance.case.context import REGISTRY, Case, case
from conformance.link.strays import LONE_BANG, TWICE, WATCHDOG_RULES, Stray
from conformance.run.runner import run_case
from conformance.targets import parse_target
from conformance.verdicts.verdict import ERROR, FAIL, INFO, NON_STRICT, PASS
from gve_fixtures.rules import load_rules


def _toy(body, *, rules=("10.3.st6.free", "5.code.ok"), tag="M") -> Case:
    return Case("99.toy.case", body, rule="toy", tag=tag, source="test", rules=rules)


@pytest.fixture
def target():
    t = parse_target("emu:GVE84-100")
    t.info = dataclasses.replace(t.info, strict=False)      # graded as a third party's
    return t


@pytest.mark.parametrize(("rule", "verdict"), [
    ("10.3.st6.free", INFO),        # [D-info] in rules.toml
    ("5.code.ok", FAIL),            # [M]
])
def test_a_failed_check_is_graded_by_its_rules_tag(target, rule, verdict):
    r = run_case(_toy(lambda ctx: ctx.expect(False, "x", rule=rule)), target)
    assert r.verdict == verdict
    assert r.checks[0]["rule"] == rule and r.checks[0]["tag"] == load_rules()[rule].tag


def test_a_d_rule_is_non_strict_where_the_decisions_are_not_implemented(target):
    r = run_case(_toy(lambda ctx: ctx.expect(False, "x", rule="3.frame.upper-case"),
                      rules=("3.frame.upper-case",)), target)
    assert r.verdict == NON_STRICT


def test_an_explicit_tag_outranks_the_rule(target):
    r = run_case(_toy(lambda ctx: ctx.expect(False, "x", rule="10.3.st6.free",
                                             tag="always")), target)
    assert r.verdict == FAIL


def test_the_only_rule_of_a_case_is_the_rule_of_its_checks(target):
    r = run_case(_toy(lambda ctx: ctx.expect(False, "x"), rules=("10.3.st6.free",)), target)
    assert r.verdict == INFO and r.checks[0]["rule"] == "10.3.st6.free"


def test_a_check_naming_a_rule_its_case_does_not_list_is_a_defect(target):
    r = run_case(_toy(lambda ctx: ctx.expect(True, "x", rule="3.frame.upper-case")), target)
    assert r.verdict == ERROR


def test_a_case_quotes_its_first_rule():
    try:
        case("99.toy.quoted", rules=("5.code.range",))(lambda ctx: None)
        c = REGISTRY["99.toy.quoted"]
        rule = load_rules()["5.code.range"]
        assert (c.rule, c.tag, c.source) == (rule.text, rule.tag, rule.source)
        with pytest.raises(ValueError, match="unknown rule"):
            case("99.toy.unknown", rules=("5.code.nope",))(lambda ctx: None)
        with pytest.raises(ValueError, match="name its rules"):
            case("99.toy.bare", rules=())(lambda ctx: None)
    finally:
        REGISTRY.pop("99.toy.quoted", None)


def test_a_case_cites_the_sources_of_all_its_rules_once_each():
    try:
        case("99.toy.cited", rules=("5.code.range", "10.cmd.status-words", "5.code.unknown"))(
            lambda ctx: None)
        assert REGISTRY["99.toy.cited"].source == "M84 12.6; M84 12.5.11"
    finally:
        REGISTRY.pop("99.toy.cited", None)


def test_a_case_cannot_write_its_requirement_again():
    with pytest.raises(TypeError):
        case("99.toy.restated", rules=("5.code.range",), rule="out of range")(lambda ctx: None)
    with pytest.raises(TypeError):
        case("99.toy.restated", rules=("5.code.range",), source="M84 12.6")(lambda ctx: None)
    with pytest.raises(ValueError, match="restates its first rule"):
        case("99.toy.restated", rules=("5.code.range",), tag="M-ex")(lambda ctx: None)
    assert "99.toy.restated" not in REGISTRY


def test_a_case_may_grade_by_another_of_its_rules_tags():
    try:
        case("99.toy.regraded", rules=("8.index.queries-uncounted", "8.index.counts"),
             tag="M")(lambda ctx: None)
        assert REGISTRY["99.toy.regraded"].tag == "M"
    finally:
        REGISTRY.pop("99.toy.regraded", None)


def test_every_case_of_the_catalogue_names_known_rules():
    from conformance.run.selection import select
    rules = load_rules()
    for c in select():
        assert c.rules, f"{c.id} names no rule"
        assert all(r in rules for r in c.rules)


def test_a_trace_is_kept_with_the_result_as_json(target):
    def body(ctx):
        ctx.trace("toy", samples=[(0.5, [1, 2, 3])], model=[(0.0, [0, 0, 0]), (0.5, [1, 2, 3])],
                  tolerance={"seconds": 0.0, "steps": 0}, params={"V": 1000})
        ctx.expect(True, "traced", rule="5.code.ok")
    r = run_case(_toy(body), target)
    assert r.verdict == PASS
    (trace,) = json.loads(json.dumps(r.to_dict()))["traces"]
    assert trace == {"name": "toy", "samples": [[0.5, [1, 2, 3]]],
                     "model": [[0.0, [0, 0, 0]], [0.5, [1, 2, 3]]],
                     "tolerance": {"seconds": 0.0, "steps": 0}, "params": {"V": 1000}}


def test_a_check_of_a_case_whose_rules_grade_differently_must_name_its_rule(target):
    r = run_case(_toy(lambda ctx: ctx.expect(True, "which rule?")), target)
    assert r.verdict == ERROR and "must name its rule" in r.notes[0]


def test_a_declared_tag_that_contradicts_the_rules_is_refused():
    with pytest.raises(ValueError, match="declared tag D contradicts its rules, tagged M"):
        case("99.toy.contradicting", rules=("8.index.counts",), tag="D")(lambda ctx: None)
    assert "99.toy.contradicting" not in REGISTRY


def test_a_case_s_tag_is_its_first_rule_s():
    try:
        case("99.toy.derived", rules=("8.index.queries-uncounted", "8.index.counts"))(
            lambda ctx: None)
        assert REGISTRY["99.toy.derived"].tag == "D"
    finally:
        REGISTRY.pop("99.toy.derived", None)


def test_a_check_of_a_case_with_several_rules_alike_must_name_its_rule(target):
    # both [M]: the case's tag would grade it right, but the report could not say which
    r = run_case(_toy(lambda ctx: ctx.expect(False, "which rule?"),
                      rules=("5.code.ok", "8.index.counts")), target)
    assert r.verdict == ERROR and "must name its rule" in r.notes[0]


def test_an_always_check_names_its_rule_too(target):
    r = run_case(_toy(lambda ctx: ctx.expect(False, "x", tag="always")), target)
    assert r.verdict == ERROR and "must name its rule" in r.notes[0]


def test_a_machinery_check_names_a_rule_its_case_does_not_list(target):
    r = run_case(_toy(lambda ctx: ctx.expect(False, "answered twice", tag="always",
                                             rule="2.link.simplex", machinery=True)), target)
    assert r.verdict == FAIL and r.checks[0]["rule"] == "2.link.simplex"


def test_a_machinery_check_names_a_known_rule(target):
    r = run_case(_toy(lambda ctx: ctx.expect(False, "x", rule="9.nothing", machinery=True)),
                 target)
    assert r.verdict == ERROR


def test_a_second_answer_fails_the_case_naming_the_link_s_rule(target):
    def answered_twice(ctx):
        ctx.link.send("?")
        ctx.link.violations.append(Stray("answered twice: !0?\\r got 0,..., then 0", TWICE))
        ctx.expect(True, "the answer", rule="5.code.ok")
    r = run_case(_toy(answered_twice), target)
    failed = [c for c in r.checks if not c["ok"]]
    assert r.verdict == FAIL
    assert [(c["rule"], c["tag"]) for c in failed] == [("2.link.simplex", "always")]


def test_a_watchdog_s_answer_is_graded_by_the_watchdog_s_rule(target):
    def ended(ctx):
        ctx.link.violations.append(Stray("a lone '!' was ended by a watchdog answering 2",
                                         WATCHDOG_RULES[LONE_BANG], always=False))
        ctx.expect(True, "the answer", rule="5.code.ok")
    r = run_case(_toy(ended), target)
    assert r.verdict == NON_STRICT
    assert [c["rule"] for c in r.checks if not c["ok"]] == ["3.frame.watchdog-lone-bang"]


@pytest.mark.parametrize(("reads", "verdict"), [([7, 8], PASS), ([8, 7], FAIL)])
def test_an_equality_check_reports_the_reading_it_judged(target, reads, verdict):
    # a reading that changes between two reads (a moving unit's PF): read once, judged
    # and reported alike
    left = iter(reads)
    r = run_case(_toy(lambda ctx: ctx.expect_equal(next(left), 7, "x", rule="5.code.ok")),
                 target)
    assert r.verdict == verdict
    assert (r.checks[0]["observed"], r.checks[0]["expected"]) == (str(reads[0]), "7")
    assert next(left) == reads[1]                      # the value was read once
