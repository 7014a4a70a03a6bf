"""A unit that moves by another amount than its frames say, judged as a real unit (the
emulator in process in virtual time behind a serial-like target, no rig: as over a pty):
its counters then disagree with where the guard's frames put the axes. The guard stops
motion until the axes are located, as after a restart, but no restart is said (the
power-on counters of spec 9 were not read) and the case that read the counters judges
them: a FAIL of its own rule, with the frames that led there."""

from __future__ import annotations

import pytest

from conformance.run.runner import run
from conformance.run.selection import select
from conformance.verdicts.verdict import COULD_NOT_TEST, ERROR, FAIL, FAILED, overall
from tests.conformance.safety.units import virtual_unit

#: mutant -> (profile, the cases run, the case (or the first of its area) that must FAIL
#: it, the rule it names)
WRONG_AMOUNTS = {
    # M2 moves 2 sixteenths a step and M8 moves 8: PF reads 120 where the frames made 480
    "microstep-modes-swapped": ("GVE54", ["10.7.*"], "10.7.", "10.7.motor.modes"),
    # the refused C takes the last queued vector's place: X ends 1 off, Y 3 beyond
    "refused-vector-overwrites": ("GVE84-100", ["10.1.*", "10.4.go.*"],
                                  "10.1.queue.refused-leaves-queue",
                                  "4.response.failed-not-executed"),
}


@pytest.mark.parametrize("mutant", sorted(WRONG_AMOUNTS))
def test_a_unit_that_moves_by_a_wrong_amount_fails_its_own_case_and_is_no_restart(mutant):
    profile, globs, caught_by, rule = WRONG_AMOUNTS[mutant]
    unit = virtual_unit(profile, rig=False, mutant=mutant)
    result = run([unit], select(globs))
    # the first case that read the counters wrong judges them; the later ones cannot move
    caught = next((r for r in result.results if r.id.startswith(caught_by)
                   and r.verdict == FAIL), None)
    assert caught is not None, [(r.id, r.verdict) for r in result.results]
    assert caught.verdict == FAIL, (caught.verdict, caught.notes)
    failed = [c for c in caught.checks if not c["ok"]]
    assert failed and failed[0]["rule"] == rule
    # the frames that led there are in the case's own log
    assert caught.wire_log and any("PF" in line for line in caught.wire_log)
    guard = unit.session.guard
    assert guard.restarts == [] and len(guard.untracked) == 1
    everything = " ".join([*result.problems, *(n for r in result.results for n in r.notes)])
    assert "restart" not in everything
    assert "disagree with the frames" in result.problems[0]
    assert "frames: " in result.problems[0]           # the frames since the last agreement
    # nothing moves until the axes are located: later motion could not test, no ERROR
    assert guard.lost
    assert any(r.verdict == COULD_NOT_TEST and "no motion" in " ".join(r.notes)
               for r in result.results)
    assert ERROR not in {r.verdict for r in result.results}
    assert overall(result.results, result.interrupted, result.problems)[0] == FAILED
    assert unit.state()["mutant"] == mutant
