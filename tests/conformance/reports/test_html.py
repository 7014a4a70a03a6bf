"""The HTML page: banner, metadata, matrix with section names, filters, folded logs and
checks, pictures (and none without matplotlib), hostile bytes made harmless."""

from __future__ import annotations

import re
import sys
from html.parser import HTMLParser

from conformance.reports import plots
from conformance.reports.html import render_html
from conformance.verdicts.verdict import ERROR
from tests.conformance.reports.toy import HOSTILE, result, toy_run


class _Tags(HTMLParser):
    """Collects start tags and checks that every opened element (but the void ones)
    is closed in order: the page is well nested."""
    VOID = frozenset({"meta", "input", "br", "img", "link", "path", "use", "rect", "stop"})

    def __init__(self) -> None:
        super().__init__()
        self.stack: list[str] = []
        self.starts: list[tuple[str, dict]] = []

    def handle_starttag(self, tag, attrs):
        self.starts.append((tag, dict(attrs)))
        if tag not in self.VOID:
            self.stack.append(tag)

    def handle_startendtag(self, tag, attrs):
        self.starts.append((tag, dict(attrs)))

    def handle_endtag(self, tag):
        if tag in self.VOID:
            return
        assert self.stack and self.stack[-1] == tag, f"</{tag}> closes {self.stack[-3:]}"
        self.stack.pop()


def parse(page: str) -> _Tags:
    p = _Tags()
    p.feed(page)
    p.close()
    assert p.stack == [], p.stack
    return p


def test_banner_and_metadata_head_the_page(no_plots):
    page = render_html(toy_run())
    assert re.search(r"class='banner FAILED'>FAILED<", page)
    top = page[:page.index("id='cases'")]
    for shown in ("2026-11-25T10:00:00+01:00", "J. Novák", "IP84 v3 27.1.2010", "25020304",
                  "--seed", "1234", "--max-travel", "2000", "--cases", "10.*",
                  "suite version", "host"):
        assert shown in top, shown
    run = toy_run()
    run.results = [r for r in run.results if r.verdict != "FAIL"]
    # nothing failed, yet the hand case was not tested: not a pass
    assert re.search(r"class='banner INCOMPLETE'>INCOMPLETE<", render_html(run))
    run.results = [r for r in run.results if r.verdict != "COULD-NOT-TEST"]
    assert re.search(r"class='banner PASSED'>PASSED<", render_html(run))


def test_the_matrix_names_sections_and_links_to_cases(no_plots):
    page = render_html(toy_run())
    tags = parse(page)
    assert "10.5 KEEP / RESTORE" in page and "6 Checksums" in page   # spec headings
    links = [a for t, a in tags.starts if t == "a" and a.get("data-verdict") == "FAIL"]
    assert links and links[0]["href"] == "#sec-6" and links[0]["data-section"] == "6"
    ids = {a.get("id") for _, a in tags.starts}
    assert "sec-6" in ids and "case-6.toy.fails-GVE84-100" in ids
    # the filters: one box per verdict, a section list, the script that applies them
    boxes = [a["value"] for t, a in tags.starts if t == "input" and a.get("type") == "checkbox"]
    assert "NON-STRICT" in boxes and "COULD-NOT-TEST" in boxes
    assert "document.querySelectorAll('details.case')" in page


def test_could_not_test_says_why_on_its_line(no_plots):
    page = render_html(toy_run())
    line = re.search(r"<summary><b>COULD-NOT-TEST</b>.*?</summary>", page).group(0)
    assert "nobody grounded IN0 (X limit)" in line


def test_passing_logs_and_checks_are_folded_unless_full_logs(no_plots):
    page = render_html(toy_run())
    assert "98 lines left out" in page and "and 49 more passed checks" in page
    assert "0.000000050 &gt; !0@" not in page
    full = render_html(toy_run(full_logs=True))
    assert "lines left out" not in full and "0.000000050 &gt; !0@" in full


def test_hostile_unit_bytes_are_harmless(no_plots):
    run = toy_run()
    run.results.append(result("5.toy.broken", ERROR, notes=[HOSTILE]))
    page = render_html(run)
    parse(page)
    assert "\x00" not in page and "\x1b" not in page and "\x7f" not in page
    assert "<script>alert" not in page and "</pre><script>" not in page
    assert "&lt;/pre&gt;&lt;script&gt;alert(1)" in page and "\\x00\\x07\\x1B" in page


def test_motion_traces_are_drawn_as_inline_svg():
    page = render_html(toy_run())
    case = page[page.index("id='case-10.2.toy.moves-GVE84-100'"):]
    case = case[:case.index("</details>")]
    assert "<svg" in case and "trapezoid X" in case
    assert page.count("<svg") == 1                 # the case's: the bars are the page's
    assert "<?xml" not in page and "<!DOCTYPE svg" not in page


def _bar(page: str, title: str) -> str:
    bars = page[page.index("<div class='bars'>"):page.index("<table>")]
    return re.search(rf"<span class='label'>{re.escape(title)}</span>(.*?)</div>", bars)[1]


def test_the_verdicts_of_each_section_are_a_bar_the_page_draws_itself():
    """A bar per section, its case runs stacked by verdict (each a link that filters the
    cases), as wide as its share of the largest section's; no picture, no plotting."""
    run = toy_run()
    run.results += [result("6.toy.more", "PASS"), result("6.toy.again", "PASS"),
                    result("6.toy.other", "FAIL")]
    page = render_html(run)
    parse(page)
    six = _bar(page, "6 Checksums")
    assert "width:100.0%" in six
    assert re.findall(r"<a class='([A-Z-]+)' style='flex-grow:(\d+)'", six) == [
        ("FAIL", "2"), ("PASS", "2")]
    assert "data-section='6' data-verdict='FAIL'" in six
    eight = _bar(page, "8 Index @ and repeat &gt;")
    assert "width:25.0%" in eight and "class='NON-STRICT' style='flex-grow:1'" in eight
    assert "<svg" not in page[page.index("<div class='bars'>"):page.index("<table>")]


def test_a_case_passing_on_several_profiles_shows_once():
    run = toy_run()
    twin = result("10.2.toy.moves", "PASS", traces=run.results[1].traces)
    twin.profile = "GVE84-50"
    run.results.append(twin)
    page = render_html(run)
    assert page.count("trapezoid X") == 1 and page.count("<b>PASS</b> 10.2.toy.moves") == 1
    assert "10.2.toy.moves [GVE84-100, GVE84-50]" in page and "Passed on 2 profiles" in page
    each = render_html(run, full_logs=True)
    assert each.count("<b>PASS</b> 10.2.toy.moves") == 2


def test_without_matplotlib_the_page_says_plots_are_off(monkeypatch):
    monkeypatch.setitem(sys.modules, "matplotlib", None)        # import fails
    plots.available.cache_clear()
    try:
        page = render_html(toy_run())
    finally:
        plots.available.cache_clear()
    parse(page)
    assert "<svg" not in page
    assert "Plots are off" in page and "trapezoid X: plots are off" in page


def test_a_rule_s_markdown_is_set_as_html_not_shown():
    from conformance.reports.text import rule_html
    assert rule_html("`H` brakes on its **ramp**") == "<code>H</code> brakes on its <b>ramp</b>"
    # escaped first: a code span of markup stays text
    assert rule_html("`<script>`") == "<code>&lt;script&gt;</code>"
    run = toy_run()
    run.results[0].rule = "`SW6` setting INTA starts a stop ramp"
    page = render_html(run)
    assert "<code>SW6</code> setting INTA" in page and "`SW6`" not in page


#: a target's answer built to break a page: markup, an ampersand, both quotes, controls
ANSWER = "8,D0<script>alert('x')</script> & \"q\" \x00\x1b[2J\x7f"


class _Text(HTMLParser):
    def __init__(self) -> None:
        super().__init__()
        self.text = ""

    def handle_data(self, data):
        self.text += data


def test_a_hostile_answer_is_shown_escaped_and_never_raw(no_plots):
    run = toy_run()
    bad = result("4.toy.answer", "FAIL", notes=[ANSWER], wire_log=["# link", f"< {ANSWER}"],
                 checks=[{"ok": False, "what": "the answer to Q", "observed": ANSWER,
                          "expected": "8,D0", "tag": "M", "rule": "a rule"}])
    run.results.append(bad)
    run.meta.target("emu:GVE84-100").version = ANSWER
    page = render_html(run)
    tags = parse(page)
    # raw, none of it: no markup of the target's, no quote or ampersand it sent
    assert [t for t, _ in tags.starts].count("script") == 1        # the page's own
    assert "<script>alert" not in page and "'x'" not in page and '"q"' not in page
    assert "& \"" not in page and not any(c in page for c in "\x00\x1b\x7f")
    # shown, everywhere it appears: the failed table, the check, the note, the wire
    # log and the units' table read back as the very text, its controls spelled out
    reader = _Text()
    reader.feed(page)
    shown = "8,D0<script>alert('x')</script> & \"q\" \\x00\\x1B[2J\\x7F"
    assert reader.text.count(shown) == 5


def test_the_rules_no_case_can_fail_are_listed_in_the_spec_s_order():
    """10 after 9 in the page's coverage, as everywhere sections are listed."""
    from conformance.reports.html import _coverage
    run = toy_run()
    run.meta.coverage = [{"profile": "GVE84-100", "covered": 1, "total": 4, "sections": [
        {"section": "10", "covered": 1, "uncovered": ["10.cmd.b", "10.cmd.a"]},
        {"section": "9", "covered": 0, "uncovered": ["9.reset.a"]}]}]
    view = _coverage(run)
    assert [rule for rule, _ in view["uncovered"]] == ["9.reset.a", "10.cmd.a", "10.cmd.b"]
    assert [title.split()[0] for title, _ in view["rows"]] == ["9", "10"]
