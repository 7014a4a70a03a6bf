"""docs/cosim.md is executable: the minimal simulator written from it alone
(examples/cosim_minimal.py) passes the golden transcripts it claims, driven over the
protocol by the suite's own client in virtual time, with the answers at the instants
the embedded emulator gives them; and, as an exec: target, it is a unit the suite runs
in virtual time without a rig."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest
import serial

import emulator  # noqa: F401  (registers gve://)
from conformance.cli import main
from conformance.run.runner import run
from conformance.run.selection import select
from conformance.targets import parse_target
from conformance.targets.cosim import CosimLine, CosimPort
from conformance.targets.program import Program
from conformance.verdicts.verdict import COULD_NOT_TEST, PASS
from gve_fixtures import golden_transcripts
from gve_fixtures.transcript import load
from tests.emulator.replay import play

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "cosim_minimal.py"
#: the golden transcripts the example answers (its module docstring says which)
PASSES = ("g1-checksum-mode", "g2-checksummed-frame", "g4a-line-idle", "g4b-position",
          "g4d-interrupted", "g4e-out-of-range", "g4f-status-read", "g9-eeprom-relay")


@pytest.fixture
def example():
    program = Program([sys.executable, str(EXAMPLE)])
    try:
        assert program.line(10) == "cosim 1"
        line = CosimLine(program, 115200)
        assert line.start().startswith("error:"), "the example has no rig"
        yield CosimPort(line, timeout=30.0)
    finally:
        program.stop()


def test_the_example_is_under_150_lines_and_names_what_it_passes():
    text = EXAMPLE.read_text()
    assert len(text.splitlines()) < 150
    claimed = " ".join(text.split('"""')[1].split())
    assert "G1, G2, G4a, G4b, G4d, G4e, G4f and G9" in claimed
    assert [name.split("-")[0].capitalize() for name in PASSES] == \
        ["G1", "G2", "G4a", "G4b", "G4d", "G4e", "G4f", "G9"]


@pytest.mark.parametrize("name", PASSES)
def test_the_example_answers_a_golden_transcript_over_the_protocol(example, name):
    (path,) = [p for p in golden_transcripts() if p.stem == name]
    assert play(example, load(path), rig=example.line) == []


def test_its_answers_come_when_the_emulator_s_do(example):
    """The same frame, the same instants: an answer's CR on the example's clock is where
    the in-process line puts it (both follow the byte time of docs/cosim.md)."""
    reference = serial.serial_for_url("gve://?model=GVE84-100", timeout=1)
    for frame in (b"!0?\r", b"!0SW2,2B\r", b"!0SR2\r", b"!0PF\r"):
        for port in (example, reference):
            port.write(frame)
        assert example.read_until(b"\r") == reference.read_until(b"\r")
        assert example.line.now == reference.line.now, frame


def test_as_an_exec_target_it_runs_in_virtual_time_without_a_rig():
    target = parse_target(f"exec:{sys.executable} {EXAMPLE}", profile="GVE84-100")
    target.preflight()
    assert target.info.virtual_time and not target.info.has_rig
    result = run([target], select(["5.errors.ok", "10.cmd.output.port"]))
    verdicts = {r.id: r.verdict for r in result.results}
    assert verdicts["5.errors.ok"] == PASS          # the known state is reached
    assert verdicts["10.cmd.output.port"] == COULD_NOT_TEST   # a rig case, and it has none
    assert target.program is None


def test_through_the_cli_it_passes_every_case_it_claims(tmp_path, capsys):
    """The README's command, as a clone author types it: the claimed goldens all PASS
    (G9 writes the EEPROM: --allow-destructive) and the run's verdict says so. In virtual
    time nothing physical moves: no --yes, and nobody at a terminal to ask."""
    cases = [arg for name in PASSES for arg in ("--cases", f"11.golden.{name}")]
    status = main(["--target", f"exec:{sys.executable} {EXAMPLE}", "--profile", "GVE84-100",
                   "--allow-destructive", "--report-dir", str(tmp_path), *cases])
    out = capsys.readouterr().out
    assert status == 0, out
    (results,) = tmp_path.glob("*/results.json")
    verdicts = {r["id"]: r["verdict"] for r in json.loads(results.read_text())["results"]}
    assert verdicts == {f"11.golden.{name}": PASS for name in PASSES}
    assert out.splitlines()[-1].startswith("PASSED")


def test_it_answers_what_docs_cosim_md_calls_malformed_with_one_error_line():
    """Bad numbers (other scripts' digits too), an instant before now or before the
    bytes' end, a missing word: one `error:` line each, the clock unchanged; an empty line
    gets no reply."""
    commands = ["until x", "until \u00b2", "tx 21303F0D 1", "tx ZZ", "baud 0", "tx", "",
                "until 5", "quit"]
    done = subprocess.run([sys.executable, str(EXAMPLE)], input="\n".join(commands) + "\n",
                          capture_output=True, text=True, timeout=30, check=True)
    replies = done.stdout.splitlines()
    assert replies[0] == "cosim 1"
    assert [r.split(":")[0] for r in replies[1:7]] == ["error"] * 6, replies
    assert replies[7:] == ["now 5"]
