"""Why a case got its verdict: the check that decided it (a broken manual's rule before
a decision, on a target graded strictly too), its rule, tag and the rule's sentence; the
note for a verdict no check made."""

from __future__ import annotations

from conformance.verdicts.explain import deciding_check, plain, reason
from conformance.verdicts.verdict import COULD_NOT_TEST, ERROR, FAIL, INFO, NON_STRICT
from gve_fixtures.rules import load_rules
from tests.conformance.reports.toy import result


def _check(tag: str, rule: str, what: str) -> dict:
    return {"ok": False, "what": what, "observed": "code 4", "expected": "code 5", "tag": tag,
            "rule": rule}


def _rules(tag: str) -> list[str]:
    return [r.id for r in load_rules().values() if r.tag == tag]


def test_a_broken_manual_rule_decides_a_fail_before_a_decision_that_failed_first():
    d, m = _rules("D")[0], _rules("M")[0]
    checks = [{"ok": True, "what": "fine", "tag": "M", "rule": m},
              _check("D", d, "our reading"), _check("M", m, "the manual's rule")]
    assert deciding_check(checks, FAIL)["rule"] == m
    why = reason(result("1.toy.mixed", FAIL, checks=checks))
    rule = load_rules()[m]
    assert (why.rule_id, why.tag, why.rule, why.source) == (m, "M", rule.text, rule.source)
    assert why.line().startswith(f"{m} [M] the manual's rule: ")
    assert why.cites() == plain(f"{rule.text} ({rule.source})")


def test_non_strict_and_info_are_decided_by_their_own_checks():
    d, info = _rules("D")[0], _rules("D-info")[0]
    checks = [_check("D-info", info, "worth knowing"), _check("D", d, "our reading")]
    assert deciding_check(checks, NON_STRICT)["rule"] == d
    assert deciding_check(checks[:1], INFO)["rule"] == info


def test_a_verdict_no_check_made_says_why_from_its_note():
    crashed = result("5.toy.broken", ERROR, checks=[_check("M", _rules("M")[0], "x")],
                     notes=["defect of the suite:\nTraceback\n  ...\nValueError: boom"])
    why = reason(crashed)
    assert not why.checked and why.what == "defect of the suite: … ValueError: boom"
    assert why.line() == why.what
    untested = reason(result("9.toy.rig", COULD_NOT_TEST, checks=[],
                             notes=["needs a test rig"]))
    assert untested.line() == "needs a test rig" and untested.cites() == ""


def test_one_format_for_what_was_seen_and_wanted():
    why = reason(result("1.toy.x", FAIL, checks=[_check("M", _rules("M")[0], "V0 → 5")]))
    assert why.seen() == 'observed "code 4", expected "code 5"'
    nothing = reason(result("1.toy.y", FAIL, checks=[
        {"ok": False, "what": "an invariant", "observed": "", "expected": "", "tag": "M",
         "rule": ""}]))
    assert nothing.seen() == "" and nothing.line() == "[M] an invariant"


def test_a_rule_s_sentence_is_plain_text_in_a_console_and_junit_and_html_in_the_page(
        tmp_path, capsys):
    """The rules are written in Markdown (`!0SW8,F1` → `5`): the console's recap and the
    JUnit file show the text without the backticks, the HTML page sets it as code."""
    from conformance.cli import main
    rule = load_rules()["5.code.range"]
    assert "`" in rule.text
    assert main(["--target", "emu:GVE84-100?mutant=range-error-code", "--cases",
                 "5.errors.out-of-range", "--report-dir", str(tmp_path), "--run-id", "r",
                 "-q"]) == 1
    out = capsys.readouterr().out
    sentence = rule.text.replace("`", "")
    assert f"the rule: {sentence} ({rule.source})" in out and "`" not in out, out
    junit = (tmp_path / "r" / "junit.xml").read_text()
    assert f"the rule: {sentence}" in junit and "`" not in junit
    page = (tmp_path / "r" / "report.html").read_text()
    assert "<code>!0SW8,F1</code>" in page and "`" not in page
