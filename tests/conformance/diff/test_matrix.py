"""The state x command x observer matrix: derived from the catalogue, the worked examples
and the profile; every cell either runs or says why not; the emulator agrees with itself
in every cell; the bugs of the areas the matrix reaches are found there and named by a
rule of their area."""

from __future__ import annotations

import pytest

from conformance.diff.engine import Pair
from conformance.diff.grammar import Options
from conformance.diff.matrix import cells, forms, summary, worked_forms
from conformance.diff.sides import Side
from conformance.diff.steps import FRAME, STATE
from conformance.protocol.catalogue import catalogue
from conformance.targets import parse_target
from gve_fixtures.profile import load_profile
from tests.conformance.diff.test_engine import in_area

EVERYTHING = Options(destructive=True, rig=True)
PROFILES = ("GVE84-100", "GVE54", "GVE114-500")


@pytest.mark.parametrize("name", PROFILES)
def test_every_cell_runs_or_says_why(name):
    every = cells(load_profile(name), EVERYTHING)
    plain = cells(load_profile(name), Options())
    assert len(every) == len(plain) > 400
    for c in every:
        assert bool(c.steps) != bool(c.left_out), c
    # a run without a rig or --allow-destructive sends fewer, and says which and why
    left = {c.left_out for c in plain if c.left_out and not c.meaningless}
    assert left == {"needs a test rig", "needs --allow-destructive"}
    assert summary(plain).startswith(f"matrix: {sum(1 for c in plain if c.steps)} of "
                                     f"{len(plain)} cells (left out: ")


def test_a_state_the_model_lacks_is_listed_not_skipped():
    gve54 = cells(load_profile("GVE54"), EVERYTHING)
    checksums = [c for c in gve54 if c.state == "checksums"]
    assert checksums and all(c.meaningless and "has no such state" in c.left_out
                             for c in checksums)
    assert any(c.state == "mode-4" and c.steps for c in gve54)
    assert any(c.state == "current-U" and c.steps for c in gve54)


def test_forms_are_the_catalogues_and_the_manuals():
    p = load_profile("GVE114-500")
    every = forms(p, [c.known_as for c in catalogue().values()])
    # a catalogue example, a worked example's frame, the A axis alone, SW6's own examples
    assert {"L1,2,3,4", "V300", "L0,0,0,100", "SW6,80"} <= set(every)
    assert "V300" in worked_forms("GVE114").get("V", [])
    assert len(every) == len(set(every))


def test_every_cell_reads_every_observer_and_the_rig():
    p = load_profile("GVE84-100")
    cell = next(c for c in cells(p, EVERYTHING) if c.state == "halted-held" and c.form == "O0,FB")
    bodies = [s.body for s in cell.steps if s.kind == FRAME]
    assert bodies[bodies.index("O0,FB") + 1:][:4] == ["P", "PF", "SR0", "SR1"]
    assert "G" in bodies and bodies.count("PF") == 4
    assert sum(s.kind == STATE for s in cell.steps) == 3


@pytest.mark.parametrize("name", PROFILES)
def test_the_emulator_agrees_with_itself_in_every_cell(name):
    target = parse_target(f"emu:{name}", allow_destructive=True)
    pair = Pair(Side(target), Side(parse_target(f"emu:{name}")), target.profile)
    runnable = [c for c in cells(target.profile, EVERYTHING) if c.steps]
    found = []
    for c in runnable:
        out = pair.run(list(c.steps))
        if out.disagreement is not None:
            found.append((c.name, out.disagreement.rule))
    assert found == []


#: bugs of the areas only the matrix's states, forms and rig reads reach
MATRIX_MUTANTS = {
    "output-ignored-while-busy": "GVE84-100",
    "spindle-refuses-eeprom": "GVE114-500",
    "short-read-ignores-microstep": "GVE54",
    "current-resets-mode": "GVE54",
    "input-stop-drops-queue": "GVE54",
    "a-axis-alone-ignored": "GVE114-500",
}


@pytest.mark.parametrize("mutant", sorted(MATRIX_MUTANTS))
def test_the_matrix_finds_the_bugs_of_its_areas(mutant):
    name = MATRIX_MUTANTS[mutant]
    target = parse_target(f"emu:{name}?mutant={mutant}", allow_destructive=True)
    pair = Pair(Side(target), Side(parse_target(f"emu:{name}")), target.profile)
    rules = set()
    for c in cells(target.profile, EVERYTHING):
        if c.steps:
            d = pair.run(list(c.steps)).disagreement
            if d is not None:
                rules.add(d.rule)
                if in_area(d.rule, mutant):
                    break
    assert any(in_area(r, mutant) for r in rules), rules
