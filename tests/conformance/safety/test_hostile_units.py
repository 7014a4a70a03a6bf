"""Hostile units on a pty: a unit that says nothing, answers
twice, answers garbage, answers with markup and NUL bytes, or answers 2 s late. The run
ends by itself in bounded time, no PASS comes from a stale or doubled answer, nothing is
an ERROR, and the three reports stay well-formed. The emulator behind a proxy gives the
answers; the proxy spoils them."""

from __future__ import annotations

import json
import time
import xml.etree.ElementTree as ET

import pytest

from conformance.reports import write_reports
from conformance.run.runner import run
from conformance.run.selection import select
from conformance.targets import parse_target
from conformance.verdicts.verdict import ERROR, FAIL, PASS, failing
from tests.conformance.safety.proxy import HOSTILE, unit_behind_proxy

pytestmark = pytest.mark.pty

SOME = ["5.errors.*", "8.index.*", "11.golden.g1*"]


def _run_hostile(tmp_path, mode: str, globs: list[str] | None):
    started = time.monotonic()
    with unit_behind_proxy("--model", "GVE84-100", transform=HOSTILE[mode]) as (_, proxy):
        target = parse_target(f"serial:{proxy.path}", profile="GVE84-100", max_travel=500)
        result = run([target], select(globs))
    seconds = time.monotonic() - started
    folder = write_reports(result, tmp_path)
    ET.parse(folder / "junit.xml")
    html = (folder / "report.html").read_text(encoding="utf-8")
    # the page's own filter script is one <script>; the unit's markup stays text
    assert "\x00" not in html and "</pre><script>" not in html and "<b>x</b>" not in html
    json.loads((folder / "results.json").read_text())
    verdicts = {r.verdict for r in result.results}
    assert ERROR not in verdicts
    assert any(failing(r.verdict) for r in result.results) or result.problems
    return result, seconds


@pytest.mark.parametrize("mode", ["silent", "twice", "markup"])
def test_hostile_units_end_the_run_without_error_or_false_pass(tmp_path, mode):
    result, seconds = _run_hostile(tmp_path, mode, SOME)
    assert seconds < 60
    if mode != "markup":                 # a markup payload may still carry the right code
        assert PASS not in {r.verdict for r in result.results}
    if mode == "silent":
        assert result.results[0].verdict == FAIL
        assert "target not responding: 4 frames unanswered" in \
            result.results[0].checks[0]["what"]
        assert all("not run: target not responding" in r.notes[0]
                   for r in result.results[1:])
    if mode == "twice":
        assert all(any("answered twice" in c["what"] for c in r.failed_checks)
                   for r in result.results)


@pytest.mark.slow
@pytest.mark.parametrize("mode", sorted(HOSTILE))
def test_hostile_units_over_the_whole_catalogue(tmp_path, mode):
    result, seconds = _run_hostile(tmp_path, mode, None)
    assert seconds < 600
    if mode != "markup":
        assert PASS not in {r.verdict for r in result.results}
