"""Every clause of every `[M]` rule that says a command sets or clears a status bit has a
cell of the matrix that can fail it: the command sent where the bit stands the other way
(each state's bits, read here on the emulator), the bit's word read at once. A clause the
model makes meaningless (the GVE84 has no input behind ST1) is listed as such."""

from __future__ import annotations

import pytest

from conformance.diff.clauses import Clause, clauses, covering, missing
from conformance.diff.grammar import Grammar, Options
from conformance.diff.matrix import cells, load_matrix, observers, states
from conformance.diff.sides import Side
from conformance.diff.steps import FRAME, INPUT, WAIT
from conformance.targets import parse_target
from gve_fixtures.profile import load_profile
from gve_fixtures.protocol import St6

EVERYTHING = Options(destructive=True, rig=True)
PROFILES = ("GVE84-100", "GVE54", "GVE114-500")


def test_the_clauses_are_read_off_the_rules():
    found = {str(c) for c in clauses()}
    # the rules' own words: H sets INTA and INTCOM, G clears them and the causes, D and K
    # clear ST4..ST6, an input sets its cause bit and INTA
    assert {"10.4.halt.ramp: H sets INTCOM", "10.4.go.resume: G clears INTCOM",
            "10.4.go.resume: G clears ST5", "10.4.delete: D clears ST6",
            "10.5.keep.saves: K clears ST4", "10.3.inputs.interrupt: input sets cause",
            "10.3.inputs.interrupt: input sets INTA"} <= found
    assert all(c.bit in {*St6.__members__, "ST4", "ST5", "ST6", "cause"} for c in clauses())


@pytest.mark.parametrize("name", PROFILES)
def test_every_state_holds_the_bits_it_declares(name):
    profile = load_profile(name)
    grammar = Grammar(profile, EVERYTHING)
    declared = {s["name"]: set(s.get("bits", [])) for s in load_matrix()["state"]}
    checked = 0
    for state, setup in states(profile):
        if state not in declared or setup is None or not grammar.written.can(setup):
            continue
        side = Side(parse_target(f"emu:{name}"))
        link = side.open()
        for step in grammar.idiom(setup):
            if step.kind == FRAME:
                link.send(step.body)
            elif step.kind == WAIT:
                link.wait(step.seconds)
            elif step.kind == INPUT:
                link.rig.set_input(step.port, step.value)
        st6 = int(link.send("SR6").values[0], 16)
        seen = {bit for bit, flag in St6.__members__.items()
                if flag in (St6.RUN, St6.INTA, St6.INTCOM) and st6 & flag}
        seen |= {f"ST{n}" for n in (4, 5) if int(link.send(f"SR{n}").values[0], 16)}
        assert seen == declared[state], (state, seen)
        checked += 1
    assert checked >= 6


@pytest.mark.parametrize("name", PROFILES)
def test_every_clause_has_a_cell_that_can_fail_it(name):
    profile = load_profile(name)
    every = cells(profile, EVERYTHING, built=False)
    lacking, meaningless = missing(profile, every)
    assert lacking == [], [str(c) for c in lacking]
    # only where the model has no input behind ST1: its cause word is never set
    assert all(c.bit == "ST5" for c in meaningless)
    assert bool(meaningless) == (profile.high_mask == 0)
    cell = covering(Clause("10.4.go.resume", "G", False, "INTCOM"), every,
                    observers(profile))
    assert cell is not None and cell.state == "halted-held"


def test_without_the_state_a_clause_needs_it_is_listed():
    profile = load_profile("GVE54")
    every = [c for c in cells(profile, EVERYTHING, built=False) if c.state != "input2-held"]
    lacking, _ = missing(profile, every)
    assert {str(c) for c in lacking} == {"10.4.go.resume: G clears ST5",
                                         "10.4.delete: D clears ST5",
                                         "10.5.keep.saves: K clears ST5"}
