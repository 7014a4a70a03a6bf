"""The whole catalogue through `exec:'python -m emulator --model P --cosim'` gives the
verdicts of `emu:P`: the co-simulated unit runs in virtual time like the embedded one,
judged exactly, its machines shrinking with the `ci` settings. What differs is what a
unit the suite does not own must differ in (the envelope, at its widest, still refuses
the vectors it cannot bound; an exec: target reaches one address), each such case
COULD-NOT-TEST saying so. GVE84-100 in the default run, every profile in the slow one."""

from __future__ import annotations

import shlex
import sys

import pytest

from conformance.run.runner import run
from conformance.run.selection import select
from conformance.targets import parse_target
from conformance.verdicts.verdict import COULD_NOT_TEST
from gve_fixtures.profile import available_profiles, load_profile

#: why a case may be COULD-NOT-TEST through the co-simulator and not on emu:
ALLOWED = ("beyond the envelope", "needs a unit at address")


def cosim_target(profile: str):
    command = [sys.executable, "-m", "emulator", "--model", profile, "--cosim"]
    target = parse_target("exec:" + shlex.join(command), profile=profile,
                          allow_destructive=True,
                          max_travel=load_profile(profile).vector_range)
    target.preflight()
    return target


def compare(profile: str) -> None:
    cases = select([])
    emu = {r.id: r for r in run([parse_target(f"emu:{profile}")], cases).results}
    target = cosim_target(profile)
    assert target.info.virtual_time and target.info.has_rig
    result = run([target], cases)
    assert result.problems == []
    cosim = {r.id: r for r in result.results}
    assert cosim.keys() == emu.keys()
    differ = {k: (emu[k].verdict, cosim[k].verdict, cosim[k].notes)
              for k in emu if emu[k].verdict != cosim[k].verdict}
    for case, (_, verdict, notes) in differ.items():
        assert verdict == COULD_NOT_TEST and any(why in notes[0] for why in ALLOWED), \
            (case, differ[case], [c["what"] for c in cosim[case].failed_checks])
    assert len(differ) <= 2, differ


def test_the_catalogue_through_the_co_simulating_emulator_gives_the_emu_verdicts():
    compare("GVE84-100")


@pytest.mark.slow
@pytest.mark.parametrize("profile", [p for p in available_profiles() if p != "GVE84-100"])
def test_on_every_profile(profile):
    compare(profile)
