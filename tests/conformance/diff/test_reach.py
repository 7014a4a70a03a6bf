"""What a search reached: commands answered, table values the reference took (a range's
ends, each word, the profile's listed values), states the reference's answers show;
the grammar's tables idioms reach every value the profile lists."""

import pytest

from conformance.cli.diff import DEFAULT_EXAMPLES
from conformance.diff.engine import Budget, Pair, search
from conformance.diff.grammar import Grammar, Options
from conformance.diff.reach import Reach
from conformance.diff.sides import RoundTrip, Side
from conformance.diff.steps import FRAME, INPUT, Step
from conformance.link.framing import parse_response
from conformance.targets import parse_target
from gve_fixtures.profile import load_profile

EVERYTHING = Options(destructive=True, rig=True)


def answered(body: str, answer: bytes, address: int | None = None) -> tuple[Step, RoundTrip]:
    step = Step(FRAME, body, address=address)
    return step, RoundTrip(b"", answer, 0, 0, parse_response(answer, summed=False))


def test_a_value_counts_where_the_reference_took_it():
    r = Reach(load_profile("GVE84-100"), EVERYTHING)
    assert r.values["V=10"] is False
    r.took(*answered("V9", b"5\r"))            # refused: below the range
    assert r.values["V=10"] is False
    r.took(*answered("V10", b"0\r"))
    r.took(*answered("SW3,FF", b"0\r"))
    r.took(*answered("WY,-100,1000,50,1000", b"5\r"))   # a run's 5: W took its fields
    assert r.values["V=10"] and r.values["SW#1=3"] and r.values["SW#2=FF"]
    assert r.values["W#1=Y"] and not r.values["W#1=X"]
    assert r.commands["V"] and r.commands["W"] and not r.commands["L"]


def test_the_profile_tables_inputs_and_states_are_counted():
    r = Reach(load_profile("GVE114-500"), EVERYTHING)
    r.took(*answered("EW06,81", b"0\r"))
    r.took(*answered("V1", b"0\r", address=7))
    r.took(Step(INPUT, port=2, value=0x3F), None)
    r.took(*answered("SR6", b"0,40\r"))
    assert r.values["EW06=81"] and r.values["!7V=1"]
    assert r.values["I2 bit 6 grounded"] and r.values["I2 bit 7 grounded"]
    assert not r.values["I2 bit 0 grounded"]
    assert r.states["moving (RUN, INTA clear)"] and not r.states["idle (ST6 00)"]
    figures = r.figures()
    assert figures["states"].reached == 1 and "idle (ST6 00)" in figures["states"].missing
    assert r.line().startswith("reached: commands 2/")


def test_states_and_values_the_run_cannot_reach_are_not_counted():
    plain = Reach(load_profile("GVE54"), Options())
    assert "checksum mode on" not in plain.states and "restarted (J)" not in plain.states
    assert not any(k.startswith(("EW06", "I1 bit")) for k in plain.values)
    assert "M=4" in plain.values and "M=U" in plain.values


@pytest.mark.parametrize("name", ["GVE114-500", "GVE54", "GVE84-100"])
def test_the_sweep_of_the_tables_reaches_every_table_value(name):
    # every value of every command's fields, each value the profile's tables list, each
    # input bit grounded: all once, whatever the search then draws
    profile = load_profile(name)
    target = parse_target(f"emu:{name}")
    pair = Pair(Side(target), Side(parse_target(f"emu:{name}")), profile)
    reach = Reach(profile, EVERYTHING)
    pair.reach = reach
    for steps in Grammar(profile, EVERYTHING).sweep():
        assert pair.run(steps).disagreement is None
    assert reach.values and all(reach.values.values()), [
        k for k, ok in reach.values.items() if not ok]


@pytest.mark.slow
@pytest.mark.parametrize("profile", ["GVE84-100", "GVE54", "GVE114-500"])
def test_the_default_budget_reaches_every_command_value_and_state(profile):
    """What `gve-conformance diff --allow-destructive` tries by default (the probes, then
    the search; the emulator against itself, both with a rig) reaches every command the
    grammar sends, every table value and every state the profile can show."""
    pair = Pair(Side(parse_target(f"emu:{profile}")), Side(parse_target(f"emu:{profile}")),
                load_profile(profile))
    reach = Reach(pair.profile, EVERYTHING)
    search(pair, EVERYTHING, Budget(examples=DEFAULT_EXAMPLES), reach=reach)
    assert reach.not_reached() == [], reach.line()
