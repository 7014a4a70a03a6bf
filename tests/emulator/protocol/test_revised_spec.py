"""The interactions of the spec revision of 2026-11-25 (the eleven emulator errors and
the decisions; tests/emulator/transcripts/*.gvt, each answer written from the spec),
replayed on every profile they name, in virtual time."""

from __future__ import annotations

from pathlib import Path

import pytest

from gve_fixtures.transcript import load
from tests.emulator.replay import TRANSCRIPTS, open_line, play, transcript_cases


@pytest.mark.parametrize(("path", "profile"),
                         list(transcript_cases(sorted(TRANSCRIPTS.glob("*.gvt")))))
def test_transcript(path: Path, profile: str, tmp_path: Path) -> None:
    port = open_line(profile, eeprom=str(tmp_path / "eeprom.bin"))
    assert play(port, load(path)) == []
