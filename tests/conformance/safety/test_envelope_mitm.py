"""A run against a unit behind a man in the middle stays within its
envelope for the whole run. The emulator on a pty counts where its axes physically went
(its control channel's `excursion`, which N, N<axis>, J and W do not reset); the proxy
sees every frame. No J, W or EEPROM write goes out without --allow-destructive, and the
excursion the run reports bounds the real one."""

from __future__ import annotations

import random
import re
from pathlib import Path

import pytest

from conformance.run.runner import run
from conformance.run.selection import select
from conformance.targets import parse_target
from conformance.verdicts.verdict import ERROR, FAIL
from gve_fixtures.profile import available_profiles, load_profile
from tests.conformance.safety.proxy import unit_behind_proxy

pytestmark = pytest.mark.pty

DESTRUCTIVE = re.compile(rb"!\d(J|W|EW|EFW|EUW)", re.IGNORECASE)
#: cases that move a lot: the envelope is tested where it matters
MOVERS = ["5.errors.*", "10.1.*", "10.2.*", "10.4.*", "10.5.keep.*", "11.golden.g6*",
          "7.packet.commits-all", "10.commands.zero-axis", "7.machine.packets"]


def _within_envelope(profile: str, travel: int, globs: list[str] | None,
                     destructive: bool = False, eeprom: Path | None = None) -> dict:
    scale = load_profile(profile).position_scale
    more = ("--eeprom", str(eeprom)) if eeprom else ()
    with unit_behind_proxy("--model", profile, *more) as (emu, proxy):
        target = parse_target(f"serial:{proxy.path}", profile=profile, max_travel=travel,
                              allow_destructive=destructive)
        result = run([target], select(globs))
        state = emu.state()
    report = result.sessions[target.info.spec]
    for axis, (lo, hi) in enumerate(state["excursion"]):
        assert -travel * scale <= lo and hi <= travel * scale, (axis, lo, hi)
        bound_lo, bound_hi = report["excursion"][axis]
        assert bound_lo * scale <= lo and hi <= bound_hi * scale, "the bound misses real travel"
    assert destructive or not [f for f in proxy.sent() if DESTRUCTIVE.match(f)]
    assert state["physical"] == [0] * len(state["physical"])     # back where it began
    assert result.problems == []
    assert ERROR not in result.counts()
    return {"profile": profile, "travel": travel, "excursion": state["excursion"],
            "bound": report["excursion"], "counts": result.counts(),
            "failed": [(r.id, r.failed_checks[0]["what"][:80]) for r in result.results
                       if r.verdict == FAIL]}


def test_the_envelope_holds_across_counter_resets_cases_and_examples():
    figures = _within_envelope("GVE84-100", 500, MOVERS)
    print(figures)
    assert figures["counts"].get("PASS")


@pytest.mark.slow
@pytest.mark.parametrize("travel", [2000, 500])
@pytest.mark.parametrize("profile", available_profiles())
def test_every_profile_stays_within_its_envelope_for_the_whole_catalogue(profile, travel):
    figures = _within_envelope(profile, travel, None)   # (each axis checked there)
    print(figures)
    assert figures["counts"].get("PASS")                # the catalogue did run


@pytest.mark.slow
@pytest.mark.parametrize("profile", ["GVE54", "GVE84-100", "GVE114-500"])
def test_destructive_runs_stay_within_the_envelope_and_leave_eeprom_as_found(tmp_path, profile):
    """J restarts the unit and zeroes its counters, W runs to a switch (none here: the
    whole travel): the odometer carries on; the EEPROM of random bytes (06 = FF: the
    GVE114's hand-wheel stays inert) is byte for byte as found."""
    image = tmp_path / "unit.eeprom"
    data = bytearray(random.Random(profile).randbytes(256))
    data[6] = 0xFF
    image.write_bytes(bytes(data))
    print(_within_envelope(profile, 500, None, destructive=True, eeprom=image))
    assert image.read_bytes() == bytes(data)
