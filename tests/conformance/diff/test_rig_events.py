"""`diff`'s grammar draws the rig's hands (an input, a reference switch, a power-on) where
both sides have a rig, and frames to every address the model serves (the GVE114's
spindle's, beyond `V`); both sides receive each alike. The search alone (no probes, no
tables, no matrix) finds, within its default budget and from a fixed seed, the bugs only
such an event or such a frame shows, in process and through the emulator's --cosim, and
names a rule of their area."""

from __future__ import annotations

import shlex
import sys

import pytest

from conformance.cli.diff import DEFAULT_EXAMPLES
from conformance.diff.engine import Budget, Pair, search
from conformance.diff.grammar import Grammar, Options
from conformance.diff.gvt import steps_of, transcript
from conformance.diff.labels import command_of
from conformance.diff.sides import Side
from conformance.diff.steps import FRAME, RIG, WAIT, Step
from conformance.targets import parse_target
from conformance.targets.emu import mutants
from gve_fixtures.profile import load_profile
from gve_fixtures.transcript import parse
from tests.conformance.diff.test_engine import EVERYTHING, in_area

#: bugs no frame at the unit's own address and no plain sequence shows: a rig's act, or
#: a frame to the spindle's address, is what they need (mutant -> profile)
RIG_OR_ADDRESS = {
    "input-stop-drops-queue": "GVE54",
    "power-on-keeps-checksums": "GVE84-100",
    "spindle-refuses-eeprom": "GVE114-500",
}


def _drawn(grammar: Grammar, n: int = 400, kind: str = "group") -> list[Step]:
    from hypothesis import HealthCheck, given, settings
    from hypothesis import strategies as st

    out: list[Step] = []

    @settings(max_examples=n, database=None, derandomize=True,
              suppress_health_check=list(HealthCheck))
    @given(st.composite(lambda draw: getattr(grammar, kind)(draw))())
    def each(group):
        out.extend(group)

    each()
    return out


def test_the_rig_events_are_drawn_only_where_both_sides_have_a_rig():
    p = load_profile("GVE84-100")
    with_rig = Grammar(p, EVERYTHING)
    assert {"power-on", "switch", "input"} <= set(with_rig.kinds)
    without = Grammar(p, Options(destructive=True))
    assert not {"power-on", "switch", "input"} & set(without.kinds)
    assert not without.written.can(["power-on"]) and not without.written.can(["switch X 10"])
    # a switch only W sees: not drawn where W is not (no --allow-destructive)
    assert "switch" not in Grammar(p, Options(rig=True)).kinds
    steps = _drawn(with_rig)
    rig = [s for s in steps if s.kind == RIG]
    assert {s.body.split()[0] for s in rig} == {"power-on", "switch"}
    # a power-on is always followed by the wait out of its restart
    for i, s in enumerate(steps):
        if s.kind == RIG and s.body == "power-on":
            assert steps[i + 1].kind == WAIT
            assert steps[i + 1].seconds >= p.restart_ms / 1000


def test_every_command_the_spindle_serves_is_drawn_at_its_address():
    p = load_profile("GVE114-500")
    grammar = Grammar(p, EVERYTHING)
    # the pool drawn from: every command the profile's spindle serves
    assert set(grammar.spindle_names) == set(p.spindle.commands)
    # the spindle's draw itself: how often a group draws it is the grammar's weights'
    steps = _drawn(grammar, 600, "spindle")
    at_spindle = {command_of(s.body) for s in steps
                  if s.kind == FRAME and s.address == p.spindle.address}
    assert {"V", "ER", "EW", "%", "Q"} <= at_spindle, at_spindle
    # and one it does not serve now and then (answered 3), never a motion frame
    assert at_spindle - set(p.spindle.commands)
    assert not {"L", "C", "W", "G", "R"} & at_spindle
    # a unit without a spindle draws no frame to address 7 as answered
    gve84 = _drawn(Grammar(load_profile("GVE84-100"), EVERYTHING))
    assert not [s for s in gve84 if s.kind == FRAME and s.address == 7 and s.answer]


def test_a_rig_event_is_written_and_replayed():
    target = parse_target("emu:GVE84-100?mutant=power-on-keeps-checksums")
    p = Pair(Side(target), Side(parse_target("emu:GVE84-100")), target.profile)
    steps = Grammar(target.profile, EVERYTHING).idiom(["%+", "switch X 50", "power-on", "@"])
    out = p.run(steps)
    assert out.disagreement is not None
    assert out.disagreement.rule in ("9.reset.state", "6.checksum.mode")
    from conformance.diff.engine import Finding
    t = transcript(Finding(steps, out), profile="GVE84-100", target="t", reference="r")
    text = t.dumps()
    assert "= power-on\n" in text and "= switch X 50\n" in text
    again = steps_of(parse(text))
    assert [str(s) for s in again if s.kind == RIG] == ["switch X 50", "power-on"]
    assert p.run(again).disagreement is not None


def _hunt(p: Pair, mutant: str) -> None:
    budget = Budget(examples=DEFAULT_EXAMPLES)
    found = search(p, EVERYTHING, budget, seed=0, with_probes=False, stop_after=1)
    assert found, f"{mutant} not found in {DEFAULT_EXAMPLES} sequences"
    d = found[0].disagreement
    assert in_area(d.rule, mutant), (d.rule, [str(s) for s in found[0].steps])


@pytest.mark.parametrize("mutant", sorted(RIG_OR_ADDRESS))
def test_the_search_alone_finds_what_only_a_rig_event_or_an_address_shows(mutant):
    assert mutant in mutants()
    name = RIG_OR_ADDRESS[mutant]
    target = parse_target(f"emu:{name}?mutant={mutant}")
    _hunt(Pair(Side(target), Side(parse_target(f"emu:{name}")), target.profile), mutant)


@pytest.mark.parametrize("mutant", sorted(RIG_OR_ADDRESS))
def test_through_a_co_simulator_too(mutant):
    name = RIG_OR_ADDRESS[mutant]
    spec = "exec:" + shlex.join([sys.executable, "-m", "emulator", "--model", name,
                                 "--cosim", "--mutant", mutant])
    target = parse_target(spec, profile=name, allow_destructive=True, max_travel=65535)
    target.preflight()
    try:
        p = Pair(Side(target, target.begin()), Side(parse_target(f"emu:{name}")),
                 target.profile)
        _hunt(p, mutant)
    finally:
        target.session.finish()
        target.close()
