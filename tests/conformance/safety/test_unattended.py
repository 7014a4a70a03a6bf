"""A run on a real unit that must ask before moving and cannot ask (no --yes, standard
input not a terminal) stops before sending anything: one line on stderr, exit 2; and the
last line of a run says what was not tested and why."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from conformance.cli.usage import INCOMPLETE_STATUS
from tests.conformance.safety.proxy import unit_behind_proxy

TRANSCRIPT = Path(__file__).parents[3] / "fixtures" / "transcripts" / "g1-checksum-mode.gvt"
SAYS = "motion needs a yes and nobody can answer here (no terminal): give --yes"


def _cli(*argv: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "conformance", *argv],
                          stdin=subprocess.DEVNULL, capture_output=True, text=True,
                          timeout=120)


@pytest.fixture(scope="module")
def proxy():
    with unit_behind_proxy("--model", "GVE84-100") as (_, proxy):
        yield proxy


COMMANDS = {
    "run": lambda path: ["--target", f"serial:{path}", "--profile", "GVE84-100",
                         "--no-reports"],
    "diff": lambda path: ["diff", "--target", f"serial:{path}", "--profile", "GVE84-100",
                          "--no-reports", "--examples", "5"],
    "replay": lambda path: ["replay", str(TRANSCRIPT), "--target", f"serial:{path}",
                            "--profile", "GVE84-100"],
}


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_unattended_without_yes_sends_nothing(command, proxy):
    done = _cli(*COMMANDS[command](proxy.path))
    assert done.returncode == 2, done
    assert done.stderr.count("\n") == 1 and SAYS in done.stderr, done.stderr
    assert done.stderr.startswith("gve-conformance"), done.stderr
    assert proxy.sent() == []


def test_the_last_line_names_what_was_not_tested(proxy):
    """Behind a pty the unit has no rig, and without --allow-destructive nothing
    destructive runs: the last line counts both, by their reasons."""
    done = _cli("--target", f"serial:{proxy.path}", "--profile", "GVE84-100", "--yes",
                "--no-reports", "--cases", "5.errors.ok", "--cases", "10.cmd.output.port",
                "--cases", "10.cmd.reference.inputs", "--cases", "10.6.eeprom.refused-while-moving",
                "--cases", "10.6.eeprom.as-shipped")
    last = done.stdout.rstrip().splitlines()[-1]
    assert done.returncode == INCOMPLETE_STATUS, done.stdout + done.stderr
    assert last == ("INCOMPLETE — 1 PASS; not tested: 4 of 5 (2 need a rig or a hand "
                    "(--operator), 1 destructive, need --allow-destructive, 1 need a rig no "
                    "hand stands in for)"), last
