"""Every golden exchange of spec section 11 (fixtures/transcripts) replayed against the
emulator on every profile the transcript names."""

from __future__ import annotations

from pathlib import Path

import pytest

from gve_fixtures import golden_transcripts
from gve_fixtures.profile import available_profiles, load_profile
from gve_fixtures.transcript import load
from tests.emulator.replay import open_line, play


def cases():
    for path in golden_transcripts():
        t = load(path)
        families = t.meta.get("profiles", "").split()
        for name in available_profiles():
            p = load_profile(name)
            if families and p.family not in families and p.name not in families:
                continue
            yield pytest.param(Path(path), name, id=f"{Path(path).stem}-{name}")


@pytest.mark.parametrize(("path", "profile"), list(cases()))
def test_golden_transcript(path: Path, profile: str, tmp_path: Path) -> None:
    t = load(path)
    address = int(t.meta.get("address", "0"))
    port = open_line(profile, address, eeprom=str(tmp_path / "eeprom.bin"))
    assert play(port, t) == []
