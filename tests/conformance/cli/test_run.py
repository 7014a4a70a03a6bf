"""The suite's run from the command line: the default run's reports (banner, metadata,
size), --junitxml, --operator-name, the seed and its replay, progress lines."""

from __future__ import annotations

import contextlib
import io
import json
import xml.etree.ElementTree as ET

import pytest

from conformance.cli import main
from conformance.cli.progress import Progress
from conformance.run.selection import select
from conformance.verdicts.verdict import COULD_NOT_TEST, ERROR, FAIL, MISSING, PASS
from gve_fixtures.profile import available_profiles
from tests.conformance.reports.toy import result

#: the default run's three reports together stay under this (about 1,450 case runs:
#: some 1.5 KB each, whatever the run finds)
LIMIT = 5 * 1024 * 1024 // 2


@pytest.fixture(scope="module")
def default_run(tmp_path_factory):
    """The default run (every profile on the emulator), once for the tests below."""
    folder = tmp_path_factory.mktemp("default")
    junit = folder / "ci" / "junit.xml"
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        status = main(["--report-dir", str(folder / "reports"), "--junitxml", str(junit),
                       "--operator-name", "Technician T."])
    (run_dir,) = (folder / "reports").iterdir()
    return status, out.getvalue(), run_dir, junit


def test_the_default_run_writes_at_most_2_5_mb(default_run):
    status, _, run_dir, _ = default_run
    sizes = {p.name: p.stat().st_size for p in run_dir.iterdir()}
    assert status == 0 and set(sizes) == {"report.html", "results.json", "junit.xml"}
    assert sum(sizes.values()) <= LIMIT, sizes


def test_the_clean_emulator_passes_every_case_on_every_profile(default_run):
    """The default run is the clean emulator on every profile with every case (ci
    settings): no case FAILs or ERRs it, on any profile (the control of the mutants'
    tests, tests/conformance/test_mutants.py)."""
    _, _, run_dir, _ = default_run
    results = json.loads((run_dir / "results.json").read_text())["results"]
    assert {r["profile"] for r in results} == set(available_profiles())
    assert len(results) == len(available_profiles()) * len(select())
    bad = [f"{r['id']} [{r['profile']}]: {r['verdict']}" for r in results
           if r["verdict"] in (FAIL, ERROR)]
    assert bad == []


def test_the_default_run_reports_passed_with_its_metadata(default_run):
    _, out, run_dir, junit = default_run
    last = out.rstrip().splitlines()[-1]
    assert last.startswith("PASSED — ") and "PASS; not tested: " in last, last
    assert "seed: none (derandomized settings draw the same examples every run" in out
    page = (run_dir / "report.html").read_text()
    assert "class='banner PASSED'>PASSED<" in page and "Technician T." in page
    data = json.loads((run_dir / "results.json").read_text())
    assert data["verdict"] == "PASSED" and data["meta"]["operator"] == "Technician T."
    assert data["meta"]["started"][-6] in "+-" and data["meta"]["finished"]   # zone offset
    assert data["meta"]["command"][-2:] == ["--operator-name", "Technician T."]
    assert {t["profile"] for t in data["meta"]["targets"]} >= {"GVE54", "GVE114-500"}
    suites = ET.parse(junit).getroot().findall("testsuite")
    # the same instant, without the zone Ant's schema refuses
    assert len(suites) == 8 and all(s.get("timestamp") == data["meta"]["started"][:19]
                                    for s in suites)


def _frames(tmp_path, seed: int) -> list[str]:
    folder = tmp_path / str(seed)
    # ci settings are derandomized; a seed overrides that, so they show it cheaply
    assert main(["--target", "emu:GVE84-100", "--cases", "6.machine.*", "--settings", "ci",
                 "--seed", str(seed), "--full-logs", "--report-dir", str(folder)]) == 0
    (run_dir,) = folder.iterdir()
    (r,) = json.loads((run_dir / "results.json").read_text())["results"]
    return [line for line in r["wire_log"] if " > " in line]


def test_the_same_seed_sends_the_same_frames(tmp_path, capsys):
    first, again = _frames(tmp_path / "a", 2026), _frames(tmp_path / "b", 2026)
    assert len(first) > 50 and first == again
    assert _frames(tmp_path / "c", 2027) != first        # the seed is what decides
    assert "seed 2026 (the same examples again: --seed 2026)" in capsys.readouterr().out


def test_a_random_seed_is_printed_and_recorded(tmp_path, capsys):
    main(["--target", "emu:GVE54", "--cases", "1.profile.version", "--settings", "dev",
          "--report-dir", str(tmp_path)])
    out = capsys.readouterr().out
    seed = int(out.split("seed ", 1)[1].split()[0])
    (run_dir,) = tmp_path.iterdir()
    assert json.loads((run_dir / "results.json").read_text())["meta"]["seed"] == seed


def test_a_log_numbers_what_did_not_pass_and_says_how_far_at_every_tenth():
    """Not a terminal (a CI log): no line per PASS, a numbered line per case that did
    not pass, and a line at every tenth of the way so the log shows the run moving."""
    out = io.StringIO()
    p = Progress(20, stream=out, terminal=False)
    for _ in range(9):
        p.result(result("1.toy.a", PASS))
    p.result(result("2.toy.b", COULD_NOT_TEST, checks=[],
                    notes=["Ground input IN0 (X limit): skipped by the operator"]))
    for _ in range(10):
        p.result(result("1.toy.a", PASS))
    lines = out.getvalue().splitlines()
    assert not any("1.toy.a" in line for line in lines)
    (why,) = [line for line in lines if "2.toy.b" in line]
    assert why.startswith("[10/20] COULD-NOT-TEST")
    assert why.endswith("-- Ground input IN0 (X limit): skipped by the operator")
    tenths = [line.split("]")[0] for line in lines if line != why]
    assert tenths == [f"[{n}/20" for n in (2, 4, 6, 8, 12, 14, 16, 18, 20)]


def test_verbose_puts_every_case_in_a_log():
    out = io.StringIO()
    p = Progress(2, stream=out, terminal=False, verbose=True)
    p.result(result("1.toy.a", PASS))
    p.result(result("1.toy.c", PASS))
    lines = out.getvalue().splitlines()
    assert [line.split()[:2] for line in lines] == [["[1/2]", "PASS"], ["[2/2]", "PASS"]]


def test_a_terminal_gets_a_progress_bar_and_only_the_lines_to_read():
    out = io.StringIO()
    p = Progress(4, stream=out, terminal=True, refresh=0)
    for _ in range(2):
        p.result(result("1.toy.a", PASS))
    p.result(result("1.toy.m", MISSING, checks=[], notes=["does not apply to this profile"]))
    p.result(result("2.toy.b", COULD_NOT_TEST, checks=[], notes=["needs a test rig"]))
    p.close()
    shown = out.getvalue()
    assert "3/4" in shown and "COULD-NOT-TEST  2.toy.b" in shown
    assert "PASS" not in shown and "MISSING" not in shown     # the bar counts those
    assert shown.endswith("\r\x1b[2K")                       # the bar cleared at the end


def test_verbose_shows_every_case_on_a_terminal_and_quiet_none():
    loud, hushed = io.StringIO(), io.StringIO()
    for out, flags in ((loud, {"verbose": True}), (hushed, {"quiet": True})):
        p = Progress(2, stream=out, terminal=True, refresh=0, **flags)
        p.result(result("1.toy.a", PASS))
        p.result(result("1.toy.m", MISSING, checks=[], notes=["not in the profile"]))
        p.close()
    assert "PASS            1.toy.a" in loud.getvalue() and "MISSING" in loud.getvalue()
    assert hushed.getvalue() == ""                              # -q: no bar, no line
