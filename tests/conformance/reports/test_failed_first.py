"""The page of a failing run shows the failure first: a list of what failed right under
the banner, before any passing case, each failing case with the check that failed it
and linked to it; the fault drawn on its motion plot; no band of zero width printed or
drawn in virtual time; plain headers; each unit's state as found and as left in view."""

from __future__ import annotations

import re

import pytest

from conformance.cli import main
from conformance.reports import plots
from conformance.reports.html import render_html
from conformance.verdicts.verdict import ERROR, FAIL, NON_STRICT
from gve_fixtures.rules import load_rules
from tests.conformance.reports.test_html import parse
from tests.conformance.reports.toy import TRACE, result, toy_run

MUTANT = "halt-answers-early"
FAILING = "10.4.measured.go-from-rest"        # H answers at once, not when at rest
PASSING = "10.2.measured.cruise-at-v"         # no H in it: the mutant passes it


@pytest.fixture(scope="module")
def mutant_page(tmp_path_factory) -> str:
    """The suite run in-process on a mutant: one case it fails, one it passes."""
    folder = tmp_path_factory.mktemp("mutant")
    status = main(["--target", f"emu:GVE84-100?mutant={MUTANT}", "--cases", FAILING,
                   "--cases", PASSING, "--report-dir", str(folder), "--run-id", "m", "-q"])
    assert status == 1
    return (folder / "m" / "report.html").read_text(encoding="utf-8")


def _case(page: str, id: str) -> str:
    start = page.index(f"id='case-{id}-GVE84-100'")
    return page[start:page.index("</details>", start)]


def _svg_texts(svg: str) -> list[str]:
    return re.findall(r"<text[^>]*>([^<]*)</text>", svg)


def test_what_failed_comes_before_the_first_passing_case(mutant_page):
    page = mutant_page
    parse(page)
    listed = page.index("<h2>What failed (1)</h2>")
    assert page.index("class='banner FAILED'") < listed
    assert listed < page.index("<b>PASS</b>") and listed < page.index("<h2>Units</h2>")
    failed = page[listed:page.index("</section>", listed)]
    # the case, linked; the check that decided it: what, observed, expected, the rule
    # with its tag and the sentence it cites, and where that sentence comes from
    assert f"<a href='#case-{FAILING}-GVE84-100'><b>FAIL</b> {FAILING}</a>" in failed
    assert "H answered when the motion came to rest" in failed
    assert "answer at 512.934 ms" in failed and "at rest at 1024.793 ms" in failed
    assert "<b>10.4.go.resume [M]</b> <q><code>G</code> with INTA = 1" in failed
    assert f"({load_rules()['10.4.go.resume'].source})" in failed
    assert PASSING not in failed
    assert f"id='case-{FAILING}-GVE84-100'" in page           # where the link goes


def test_the_fault_is_drawn_on_its_motion_plot(mutant_page):
    texts = _svg_texts(_case(mutant_page, FAILING))
    assert "H answered 512.9 ms" in texts
    assert "at rest 1024.8 ms (expected)" in texts


def test_no_zero_width_band_in_virtual_time(mutant_page):
    page = mutant_page
    assert "ms line" not in page and "±0" not in page
    for id in (FAILING, PASSING):
        case = _case(page, id)
        assert "<svg" in case
        assert f"opacity: {plots.BAND_ALPHA}" not in case          # no band drawn
        assert "time (s)" in _svg_texts(case) and "band:" not in case


def test_a_band_with_a_width_is_drawn_and_named():
    svg = plots.trace_chart(TRACE, "k")                # 2 ms, 1 step: real time
    assert f"opacity: {plots.BAND_ALPHA}" in svg
    assert "time (s); band: ±2.000 ms, ±1 step(s)" in _svg_texts(svg)


def test_a_wrong_reading_is_marked_against_what_was_expected():
    trace = dict(TRACE, faults=[{"kind": "position", "t": 0.5, "axis": 0, "observed": 10,
                                 "expected": [2400, 2600]}])
    texts = _svg_texts(plots.trace_chart(trace, "k"))
    assert "read wrong" in texts and "expected there" in texts
    assert "read wrong" not in _svg_texts(plots.trace_chart(TRACE, "k"))


def test_a_chart_is_the_same_whatever_was_drawn_before_it():
    """The canvas a chart is drawn on is kept for the next: nothing of one chart (its
    marks, legend, band, limits, title) shows in the next, even one with nothing to draw."""
    marked = dict(TRACE, name="marked", params={}, tolerance={},
                  samples=[(t / 10, [0, -5 * t, 0]) for t in range(11)], model=[],
                  faults=[{"kind": "instant", "what": "H answered", "observed": 0.3,
                           "expected": [0.1, 0.2]}])
    empty = {"name": "nothing moved", "samples": [], "model": []}
    charts = [TRACE, marked, empty]
    drawn = [plots.trace_chart(trace, "k") for trace in charts + charts[::-1]]
    for n, trace in enumerate(charts):
        plots._canvas.cache_clear()                # a canvas never drawn on
        alone = plots.trace_chart(trace, "k")
        assert drawn[n] == alone == drawn[-1 - n], trace["name"]


def test_the_list_is_worst_first_and_names_a_case_once_for_its_profiles(no_plots):
    run = toy_run()
    twin = result("6.toy.fails", FAIL, checks=run.results[2].checks)
    twin.profile = "GVE84-50"
    run.results += [twin, result("5.toy.broken", ERROR, checks=[],
                                 notes=["defect of the suite:\nTraceback\n  ...\n"
                                        "ValueError: boom"])]
    page = render_html(run)
    failed = page[page.index("id='failed'"):page.index("</section>")]
    rows = re.findall(r"<tr class='([A-Z-]+)'><td><a href='#case-([^']+)'", failed)
    assert [v for v, _ in rows] == [ERROR, FAIL, NON_STRICT]
    assert "defect of the suite: … ValueError: boom" in failed
    # one line for the case on both profiles, a link to each run
    assert failed.count("6.toy.fails</a>") == 1
    assert "href='#case-6.toy.fails-GVE84-100'>GVE84-100</a>" in failed
    assert "href='#case-6.toy.fails-GVE84-50'>GVE84-50</a>" in failed
    assert "Not judged: 1 COULD-NOT-TEST" in failed


def test_a_passing_run_has_no_failure_list(no_plots):
    run = toy_run()
    run.results = [r for r in run.results if r.verdict not in (FAIL, NON_STRICT)]
    page = render_html(run)
    assert "What failed: no case" in page and "Not judged: 1 COULD-NOT-TEST" in page
    run.results = [r for r in run.results if r.verdict != "COULD-NOT-TEST"]
    assert "id='failed'" not in render_html(run)


REAL = {"target": "serial:/dev/ttyUSB0", "profile": "GVE84-100", "axes": ["X", "Y", "Z"],
        "real": True, "identity": {"version": "IP84 v3 27.1.2010", "processor_id": "25020304"},
        "max_travel": 2000, "excursion": [[-12, 1400], [0, 0], [0, 3]],
        "found": {"ST0": "00", "ST1": "04", "checksums": "off"},
        "restored": ["axes back where the run began", "ST0..ST5 as found: 00 04"],
        "reset": ["set to the reset state (they cannot be read): XM100"],
        "problems": ["EEPROM 07 not put back"], "interrupted": False, "not_responding": "",
        "violations": []}


def test_plain_headers_and_the_state_as_found_and_as_left_in_view(no_plots):
    run = toy_run()
    run.targets.append(REAL["target"])
    t = run.meta.target(REAL["target"])
    t.kind, t.profile, t.envelope = "serial", "GVE84-100", 2000
    run.sessions = {"emu:GVE84-100": {**REAL, "target": "emu:GVE84-100", "real": False},
                    REAL["target"]: REAL}
    page = render_html(run)
    parse(page)
    top = page[:page.index("<h2>Verdicts by spec section</h2>")]
    assert "<th>firmware (its answer to ?)</th>" in top \
        and "<th>processor id (its answer to Q)</th>" in top
    assert "version (?)" not in page
    assert "X -12..+1400, Y +0..+0, Z +0..+3" in top                 # the real unit
    assert "not tracked: every case starts a fresh emulated unit" in top   # the emulator
    state = top[top.index("The units as found and as left"):]
    assert "<details" not in state                                    # not behind a toggle
    for shown in ("firmware (its answer to ?): IP84 v3 27.1.2010", "status words: ST0 00, ST1 04",
                  "checksums: off", "restored: axes back where the run began",
                  "reset: set to the reset state (they cannot be read): XM100",
                  "PROBLEM: EEPROM 07 not put back",
                  "emu:GVE84-100: the embedded emulator — every case ran on a fresh unit"):
        assert shown in state, shown


@pytest.mark.parametrize("graded", ["by the tags", "strict", ""])
def test_the_check_shown_is_the_one_that_gave_the_verdict(graded, no_plots):
    """Graded by the tags a failed [D] check is NON-STRICT: a FAIL is the [M] check's;
    graded strictly the [D] check FAILs too, and the broken manual's rule still decides
    (it FAILs any target)."""
    run = toy_run()
    run.meta.target("emu:GVE84-100").graded = graded
    run.results = [result("10.toy.both", FAIL, checks=[
        {"ok": False, "what": "a D check", "observed": "1", "expected": "0", "tag": "D",
         "rule": ""},
        {"ok": False, "what": "an M check", "observed": "2", "expected": "0", "tag": "M",
         "rule": ""}])]
    page = render_html(run)
    failed = page[page.index("id='failed'"):page.index("</section>")]
    assert "<td>an M check</td>" in failed and "a D check" not in failed
