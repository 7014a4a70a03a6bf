"""The steps written in the grammar's data: idioms, probes and the tables swept whole,
left out where the profile or the run cannot send them."""

from conformance.diff.grammar import Grammar, Options, probes
from conformance.diff.labels import command_of
from conformance.diff.steps import FILL, FRAME, INPUT, WAIT
from conformance.diff.written import Written, load_probes
from gve_fixtures.profile import load_profile
from gve_fixtures.rules import load_rules

GVE54 = load_profile("GVE54")
GVE84 = load_profile("GVE84-100")


def written(profile, options: Options) -> Written:
    """The written steps of a profile and run, as its grammar holds them."""
    return Grammar(profile, options).written


def test_an_idiom_vector_gets_the_profile_axes():
    assert written(GVE84, Options())._padded("C100") == "C100,0,0"
    assert written(GVE54, Options())._padded("L-5") == "L-5" + ",0" * (len(GVE54.axes) - 1)
    assert written(GVE84, Options())._padded("C1,2,3") == "C1,2,3"


def test_an_event_repeat_is_read_whole():
    g = written(GVE84, Options())
    assert g.fixed(">").lines == 2 and g.fixed("H").lines == 1
    assert not g.fixed("*S").answer


def test_an_idiom_is_written_as_steps_on_the_profile():
    g = written(GVE84, Options(destructive=True, rig=True))
    steps = g.idiom(["wait 0.5", "input 1 FE", "fill 9 C2", "bad:V100", "stalled:?",
                     "other:?", "L300", "J"])
    assert [s.kind for s in steps] == [WAIT, INPUT, FILL, FRAME, FRAME, FRAME, FRAME, FRAME,
                                       WAIT]
    wait, inp, fill, bad, stalled, other, line, _, restart = steps
    assert (wait.seconds, inp.port, inp.value) == (0.5, 1, 0xFE)
    assert (fill.body, fill.times) == ("C2,0,0", 9)
    assert bad.checksum == "bad" and stalled.stall[1] > GVE84.watchdog_ms / 1000
    assert other.address != GVE84.address and not other.answer
    assert line.body == "L300,0,0" and restart.seconds >= GVE84.restart_ms / 1000


def test_probes_name_rules_and_are_left_out_where_they_cannot_be_sent():
    rules = load_rules()
    assert all(p["rule"] in rules for p in load_probes())
    on_gve54 = [p["rule"] for p, _ in probes(GVE54, Options(destructive=True))]
    assert "10.2.motion.path-rate" not in on_gve54           # no VK on the GVE54
    safe = [p["steps"] for p, _ in probes(GVE84, Options())]
    assert ["EW10,5A", "ER10"] not in safe
    assert ["EW10,5A", "ER10"] in [p["steps"] for p, _ in probes(GVE84, Options(True))]


def test_a_written_packets_frames_await_no_answer_until_one_ends_it():
    g = written(GVE84, Options(destructive=True))
    steps = g.idiom(["*S", "B10", "v10", "*E2", "C200", "*S", "C10", "H", "*E1", "F"])
    assert [(s.body, s.answer) for s in steps] == [
        ("*S", False), ("B10", False), ("v10", False), ("*E2", True), ("C200,0,0", True),
        ("*S", False), ("C10,0,0", False), ("H", True), ("*E1", True), ("F", True)]


def test_the_sweep_runs_each_commands_values_together_then_each_idiom():
    g = Grammar(GVE84, Options(destructive=True, rig=True))
    swept = g.sweep()
    singles = [t[0] for t in g.tables if len(t) == 1]
    bodies = [s.body for seq in swept for s in seq if s.kind == FRAME]
    assert all(b in bodies for b in singles)
    # a command's values in one sequence
    v = next(seq for seq in swept if command_of(seq[0].body) == "V")
    assert {s.body for s in v} == {b for b in singles if command_of(b) == "V"}
