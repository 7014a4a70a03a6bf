"""Every golden exchange of spec section 11 (fixtures/transcripts) replayed against the
emulator on every profile the transcript names."""

from __future__ import annotations

from pathlib import Path

import pytest

from gve_fixtures import golden_transcripts
from gve_fixtures.transcript import load
from tests.emulator.replay import open_line, play, transcript_cases


@pytest.mark.parametrize(("path", "profile"), list(transcript_cases(golden_transcripts())))
def test_golden_transcript(path: Path, profile: str, tmp_path: Path) -> None:
    t = load(path)
    address = int(t.meta.get("address", "0"))
    port = open_line(profile, address, eeprom=str(tmp_path / "eeprom.bin"))
    assert play(port, t) == []
