"""Rules coverage (conformance/run/coverage.py, gve-conformance --coverage)."""

from __future__ import annotations

import pytest

from conformance.case.context import Case
from conformance.cli import main
from conformance.run.coverage import HOST_CHECKS, coverage, format_coverage, register_host_check


def _case(id, rules, **kw) -> Case:
    return Case(id, lambda ctx: None, rule="toy", tag="M", source="test", rules=rules, **kw)


def test_a_rule_is_covered_where_a_case_naming_it_applies():
    cases = [_case("99.a.b", ("6.checksum.sum", "5.code.ok"), requires=("%",))]
    (gve54, gve84) = coverage(["GVE54", "GVE84-100"], cases=cases)
    sec5 = next(s for s in gve54.sections if s.section == "5")
    # the case needs %, which the GVE54 lacks: it cannot fail 5.code.ok there
    assert "5.code.ok" in sec5.uncovered
    assert all(s.section != "6" for s in gve54.sections)     # no section 6 rule applies
    sec6 = next(s for s in gve84.sections if s.section == "6")
    assert sec6.covered == {"6.checksum.sum": ["99.a.b"]}
    assert "6.checksum.bad-refused" in sec6.uncovered
    assert gve84.covered == 2 and gve84.total > 100


def test_host_rules_are_covered_by_registered_host_checks():
    registered = dict(HOST_CHECKS)          # the host certification's own, if imported
    HOST_CHECKS.clear()
    try:
        register_host_check("toy-host-check", ["8.recovery.no-blind-resend"])
        (pc,) = coverage(["GVE84-100"], role="host", cases=[])
        assert pc.covered == 1
        sec8 = next(s for s in pc.sections if s.section == "8")
        assert sec8.covered == {"8.recovery.no-blind-resend": ["toy-host-check"]}
        with pytest.raises(ValueError, match="host-role"):
            register_host_check("bad", ["10.3.st6.free"])     # a unit-only rule
    finally:
        HOST_CHECKS.clear()
        HOST_CHECKS.update(registered)


def test_the_table_lists_the_uncovered_rules():
    text = format_coverage(coverage(["GVE84-100"], cases=[_case("99.a.b", ("5.code.ok",))]))
    assert "5.code.ok" not in text.split("without a case")[1]
    assert "  5.code.range [M-ex] on every profile" in text


def test_the_command_prints_coverage_and_exits_0(capsys):
    assert main(["--coverage", "--profile", "GVE54"]) == 0
    out = capsys.readouterr().out
    assert "GVE54" in out and "total" in out


def test_the_command_exits_1_when_a_rule_has_no_case(capsys):
    # with only the version case selected, nearly every rule is left without one
    assert main(["--coverage", "--profile", "GVE54", "--cases", "1.profile.version"]) == 1
    assert "without a case that can fail them" in capsys.readouterr().out


def test_every_unit_rule_is_covered_on_every_profile():
    report = coverage()
    missing = {pc.profile: pc.uncovered for pc in report if pc.uncovered}
    assert not missing, format_coverage(report)


def test_the_matrix_is_counted_per_model_and_its_meaningless_cells_listed(capsys):
    (gve84, gve54) = coverage(["GVE84-100", "GVE54"], cases=[])
    for pc in (gve84, gve54):
        m = pc.matrix
        assert 0 < m.run < m.cells and m.observers >= 10 and m.lacking == []
        assert m.clauses >= 10
    # the GVE84 has no input behind ST1: that state's cells, and the clauses clearing
    # ST5, are meaningless there, listed as such; the GVE54 has the state
    assert gve84.matrix.meaningless_cells > 0 and gve84.matrix.meaningless
    assert not [n for n in gve54.matrix.left_out.get("the GVE54 has no such state", [])
                if n.startswith("input2-held")]
    assert main(["--coverage", "--profile", "GVE84-100"]) == 0
    out = capsys.readouterr().out
    assert f"cells     {gve84.matrix.run}/{gve84.matrix.cells}" in out
    assert ("cell(s) meaningless (the GVE84 has no such state): input2-held x every form"
            in out)
    assert "meaningless on the model: 10.4.go.resume: G clears ST5" in out


def test_the_report_shows_the_matrix(tmp_path):
    from conformance.reports.html import render_html
    from conformance.run.runner import RunResult

    run = RunResult("r", targets=["emu:GVE84-100"], settings="none")
    run.meta.coverage = [pc.as_dict() for pc in coverage(["GVE84-100"], cases=[])]
    for d in run.meta.coverage:
        d["sections"] = [{**s, "covered": len(s["covered"])} for s in d["sections"]]
    page = render_html(run)
    assert "state &times; command &times; observer matrix" in page
    assert "cells (state x command form) run" in page
    assert "meaningless (the GVE84 has no such state)" in page
