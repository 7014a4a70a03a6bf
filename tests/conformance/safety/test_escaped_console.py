"""A unit whose identity (its answer to `?`) carries ESC, CR, LF and NUL — escape
sequences that set a terminal's title or clear its screen, and a line break followed by
a forged verdict line: everything the suite prints of it, on the console and in the
reports' text, is escaped (``\\x1B``, ``\\n``): no raw control byte, no line of the
unit's own."""

from __future__ import annotations

import json
import re

import pytest

from conformance.cli import main
from tests.conformance.safety.proxy import unit_behind_proxy

pytestmark = pytest.mark.pty

FORGED = "PASSED — 999 PASS; everything tested"
#: the identity: a title, a cleared screen, a line of its own, a NUL, a C1 CSI
IDENTITY = (b"0,\x1b]0;pwned\x07\x1b[2J\n" + FORGED.encode() + b"\x00\x9b31m\rX\r")
#: any control character but the console's own line ends
RAW = re.compile("[\x00-\x09\x0b-\x1f\x7f-\x9f]")


def _hostile_identity(answer: bytes) -> list[tuple[float, bytes]]:
    return [(0.0, IDENTITY if answer.startswith(b"0,IP84") else answer)]


def _console(argv: list[str], capsys) -> tuple[int, str]:
    with unit_behind_proxy("--model", "GVE84-100", transform=_hostile_identity) as (_, proxy):
        status = main(["--target", f"serial:{proxy.path}", "--max-travel", "800", "--yes",
                       "--cases", "5.errors.ok", *argv])
    captured = capsys.readouterr()
    return status, captured.out + captured.err


def test_the_identity_is_printed_escaped(capsys, tmp_path):
    status, text = _console(["--profile", "GVE84-100", "--report-dir", str(tmp_path)],
                            capsys)
    assert status in (0, 1)
    assert "\\x1B]0;pwned\\x07\\x1B[2J\\nPASSED" in text, text
    assert not RAW.search(text), [line for line in text.splitlines() if RAW.search(line)]
    assert not any(line.startswith(FORGED) for line in text.splitlines())
    (folder,) = tmp_path.iterdir()
    results = json.loads((folder / "results.json").read_text())
    assert results["sessions"], "the identity is kept as data, escaped by JSON itself"
    assert "\x1b" not in (folder / "report.html").read_text()


def test_a_profile_chosen_by_the_identity_says_it_escaped(capsys):
    status, text = _console(["--profile", "auto", "--no-reports"], capsys)
    assert status == 2          # no profile knows it: one line
    assert text.count("\n") == 1 and "\\x1B]0;pwned" in text
    assert not RAW.search(text.rstrip("\n"))
