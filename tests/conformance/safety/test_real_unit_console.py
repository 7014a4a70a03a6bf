"""What a technician sees on a real unit (a pty here): the Hypothesis settings chosen for
real units, the largest excursion per axis, what was restored; the same run through the
pytest plugin leaves the unit as found."""

from __future__ import annotations

import json

import pytest

from conformance.cli import main
from conformance.targets.as_found import ROUND_TRIPS
from tests.conformance.safety.proxy import unit_behind_proxy

pytestmark = pytest.mark.pty

pytest_plugins = ["pytester"]


def test_the_console_says_what_the_session_did(tmp_path, capsys):
    with unit_behind_proxy("--model", "GVE84-100") as (_, proxy):
        status = main(["--target", f"serial:{proxy.path}", "--profile", "GVE84-100",
                       "--cases", "5.errors.ok", "--cases", "10.3.status.run-bit",
                       "--max-travel", "800", "--yes", "--report-dir", str(tmp_path)])
    out = capsys.readouterr().out
    assert status == 0
    assert "Hypothesis settings: hardware on real units" in out
    assert "largest excursion (full steps, envelope ±800): X +0..+500, Y +0..+0, Z +0..+0" \
        in out
    assert "restored: axes back where the run began" in out
    assert "restored: ST0..ST5 written back and read back as found: 00 00 00 00 00 00" in out
    (folder,) = tmp_path.iterdir()
    html = (folder / "report.html").read_text()
    assert "restored: axes back where the run began" in html and "±800" in html
    session = json.loads((folder / "results.json").read_text())["sessions"]
    assert next(iter(session.values()))["excursion"] == [[0, 500], [0, 0], [0, 0]]


def test_the_plugin_runs_one_session_and_puts_the_unit_back(pytester):
    with unit_behind_proxy("--model", "GVE84-100") as (emu, proxy):
        assert proxy.ask(b"!0SW0,05\r") == b"0\r"      # the machine's interrupt enables
        result = pytester.runpytest("--gve-target", f"serial:{proxy.path}", "--gve-profile",
                                    "GVE84-100", "--gve-yes", "--gve-cases", "5.errors.ok",
                                    "--gve-cases", "10.3.status.all-bits-stored", "-q")
        state = emu.state()
    result.assert_outcomes(passed=2)
    assert state["status"][0] == "05" and state["physical"] == [0, 0, 0]
    # one session for the whole pytest run: the unit as found is read once (the checksum
    # probe and the identity ask ? once each, then the ones that measure the line's round
    # trip), and the checksum mode is read back once at the end
    assert sum(f.startswith(b"!0?") for f in proxy.sent()) == 3 + ROUND_TRIPS


def _mpg_unit(tmp_path) -> list[str]:
    """A GVE114 whose EEPROM 06 makes its hand wheel hold RUN (spec 9): found moving."""
    image = tmp_path / "unit.eeprom"
    image.write_bytes(b"\xff" * 6 + b"\x01" + b"\xff" * 249)
    return ["--model", "GVE114-500", "--eeprom", str(image)]


def test_a_problem_makes_the_exit_status_non_zero(tmp_path, capsys):
    with unit_behind_proxy(*_mpg_unit(tmp_path)) as (_, proxy):
        status = main(["--target", f"serial:{proxy.path}", "--profile", "GVE114-500",
                       "--cases", "5.errors.ok", "--no-reports", "--yes"])
    assert status == 1
    assert "PROBLEM" in capsys.readouterr().out


def test_a_problem_fails_the_pytest_run_too(pytester, tmp_path):
    with unit_behind_proxy(*_mpg_unit(tmp_path)) as (_, proxy):
        result = pytester.runpytest("--gve-target", f"serial:{proxy.path}", "--gve-profile",
                                    "GVE114-500", "--gve-yes", "--gve-cases", "5.errors.ok", "-q")
    assert result.ret == pytest.ExitCode.TESTS_FAILED
    result.stdout.fnmatch_lines(["*PROBLEM on serial:*the unit reports RUN*"])
