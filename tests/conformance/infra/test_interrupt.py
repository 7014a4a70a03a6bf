"""Ctrl-C: the run stops, the interrupted case is reported as interrupted, and the
reports of what ran are written (the real-unit side: tests/conformance/safety)."""

from __future__ import annotations

import json

from conformance.case.context import Case
from conformance.reports import write_reports
from conformance.run.runner import run
from conformance.targets import parse_target
from conformance.verdicts.verdict import COULD_NOT_TEST, PASS


def _ok(ctx) -> None:
    ctx.expect(ctx.link.send("?") is not None, "answered")


def _interrupt(ctx) -> None:
    ctx.link.send("?")
    raise KeyboardInterrupt


def test_ctrl_c_keeps_what_ran_and_shows_the_interrupted_case(tmp_path):
    cases = [Case("1.test.before", _ok, "r", "M", "test", rules=("5.code.ok",)),
             Case("1.test.ctrl-c", _interrupt, "r", "M", "test", rules=("5.code.ok",)),
             Case("1.test.after", _ok, "r", "M", "test", rules=("5.code.ok",))]
    result = run([parse_target("emu:GVE84-100")], cases, run_id="ctrl-c")
    assert result.interrupted
    assert [(r.id, r.verdict, r.interrupted) for r in result.results] == [
        ("1.test.before", PASS, False), ("1.test.ctrl-c", COULD_NOT_TEST, True)]
    assert any("interrupted by Ctrl-C" in n for n in result.results[1].notes)
    folder = write_reports(result, tmp_path)
    written = json.loads((folder / "results.json").read_text())
    assert written["interrupted"] is True
    assert written["results"][1]["interrupted"] is True
