"""The measured motion cases: exact on the emulator's virtual clock (zero tolerance, so
none printed with the checks; a trace per scenario), and within the printed tolerance in
real time over a pseudo-terminal."""

from __future__ import annotations

import re
import subprocess
import sys

import pytest

from conformance.run.runner import run
from conformance.run.selection import select
from conformance.targets import parse_target
from conformance.verdicts.verdict import MISSING, PASS

MEASURED = ["*measured*"]
#: the band a real-time check prints: the line's, and the steps either side it allowed
TOLERANCE = re.compile(r"\(±([\d.]+) ms line, ±(\d+) steps?\)")


@pytest.mark.parametrize("profile", ["GVE84-100", "GVE54", "GVE114-500"])
def test_virtual_time_judges_every_reading_with_zero_tolerance(profile: str) -> None:
    """Exact: the band is zero, and a band of zero is not printed."""
    results = run([parse_target(f"emu:{profile}")], select(MEASURED)).results
    assert {r.verdict for r in results} <= {PASS, MISSING}
    ran = [r for r in results if r.verdict == PASS]
    assert ran
    for r in ran:
        assert r.traces and all(t["tolerance"] == {"seconds": 0.0, "steps": 0} for t in r.traces)
        for c in r.checks:
            assert ": PF at " in c["what"] or ": H answered " in c["what"], c["what"]
            assert "ms line" not in c["what"] and "±" not in c["what"], c["what"]


def test_an_acceleration_refused_beyond_a_range_no_manual_states_is_measured_at_reset():
    """A unit that takes A as one byte refuses A10000 (5): the scenario is measured at
    the reset value the manual states (A20) and judged, not left untested."""
    results = run([parse_target("emu:GVE54?reading=accel-byte-range")],
                  select(["10.2.measured.cruise-at-v", "10.2.measured.dwell"])).results
    assert [r.verdict for r in results] == [PASS, PASS], [(r.id, r.notes) for r in results]
    for r in results:
        assert any("A10000 answered 5" in n and "with A20" in n for n in r.notes), r.notes


@pytest.mark.slow
@pytest.mark.pty
@pytest.mark.parametrize("profile", ["GVE84-100", "GVE54", "GVE114-500"])
def test_real_time_over_a_pty_within_the_printed_tolerance(profile: str) -> None:
    proc = subprocess.Popen([sys.executable, "-m", "emulator", "--model", profile, "--pty"],
                            stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                            stderr=subprocess.DEVNULL, text=True)
    try:
        path = proc.stdout.readline().strip()
        target = parse_target(f"serial:{path}?baud=115200", profile=profile,
                              allow_destructive=True, max_travel=100_000)
        result = run([target], select(MEASURED))
    finally:
        proc.terminate()
        proc.wait(10)
    bad = {r.id: [c["what"] for c in r.checks if not c["ok"]][:2] for r in result.results
           if r.verdict not in (PASS, MISSING)}
    assert not bad
    bands = sorted((float(m.group(1)), int(m.group(2))) for r in result.results
                   for c in r.checks if ": PF at " in c["what"]
                   and (m := TOLERANCE.search(c["what"])))
    assert bands and all(line > 0 for line, _ in bands)      # every reading says its band
    lines, steps = sorted(b[0] for b in bands), sorted(b[1] for b in bands)
    print(f"{profile}: {len(bands)} readings in {result.seconds:.1f} s; line band median "
          f"±{lines[len(lines) // 2]:.1f} ms, widest ±{lines[-1]:.1f} ms; steps median "
          f"±{steps[len(steps) // 2]}, widest ±{steps[-1]}")
