"""`gve-conformance diff` through a co-simulator: the comparison is exact (both sides in
virtual time: positions while moving and the instants of answers too), each sequence
begins at the simulator's power-on (its EEPROM as found), one that leaves the checksum
mode on is named; the clean emulator
agrees with itself over hundreds of sequences, a mutant is found, shrunk, written and
replayed; every mutant is found as in process, with frames told ahead as without."""

from __future__ import annotations

import shlex
import sys
from pathlib import Path

import pytest

from conformance.cli.diff import main as diff_main
from conformance.cli.replay import main as replay_main
from conformance.diff.engine import Budget, KnownStateLost, Pair, search
from conformance.diff.grammar import Options, probes
from conformance.diff.sides import Side
from conformance.diff.steps import FRAME, Step
from conformance.targets import parse_target
from conformance.targets.emu import mutants
from conformance.verdicts.verdict import FAIL
from tests.conformance.diff.test_engine import (
    EVERYTHING,
    ON_THE_WIRE,
    PROFILE,
    WITHIN_PLACEMENT,
    in_area,
)


def cosim(*options: str) -> str:
    return "exec:" + shlex.join([sys.executable, "-m", "emulator", "--model", "GVE84-100",
                                 "--cosim", *options])


def pair(spec: str) -> Pair:
    target = parse_target(spec, profile="GVE84-100", allow_destructive=True)
    target.preflight()
    return Pair(Side(target, target.begin()), Side(parse_target("emu:GVE84-100")),
                target.profile)


def test_the_comparison_is_exact_and_the_clean_emulator_agrees():
    p = pair(cosim())
    assert p.exact
    try:
        budget = Budget(examples=300)
        assert search(p, Options(destructive=True, rig=True), budget) == []
        assert budget.used == 300
    finally:
        p.target.session.finish()
        p.target.target.close()


def test_a_frame_neither_side_answers_is_listened_to_as_long_on_both():
    """A W queued in a packet gets no answer: the target's guard awaits it for as long as
    the envelope lets the move last, the reference's (no envelope) far longer; both are
    listened to for the target's window, and two silences are alike."""
    p = pair(cosim())
    try:
        out = p.run([Step(FRAME, body="*S", answer=False),
                     Step(FRAME, body="WX,1,900,1,900")])
        assert out.disagreement is None and out.frames == 2, out.ended
        target, reference = out.records[1].target, out.records[1].reference
        assert target.answer == reference.answer == b""
        assert target.received_at == reference.received_at
    finally:
        p.target.session.finish()
        p.target.target.close()


def test_a_mutant_is_found_shrunk_and_replayed(tmp_path: Path, capsys):
    spec = cosim("--mutant", "velocity-ignored")
    # the probes name it within the first hundred sequences, whatever the seed
    status = diff_main(["--target", spec, "--profile", "GVE84-100", "--allow-destructive",
                        "--yes", "--examples", "100", "--report-dir", str(tmp_path)])
    out = capsys.readouterr().out
    assert status == 1, out
    assert "FAIL        10.cmd.exchange-velocity" in out or "FAIL        10.2.motion" in out
    (folder,) = tmp_path.iterdir()
    found = sorted(folder.glob("diff-*.gvt"))
    assert found
    # the shrunk transcript still shows the bug, and not on the clean emulator
    assert replay_main([str(found[0]), "--target", spec, "--allow-destructive", "--yes"]) == 1
    assert replay_main([str(found[0]), "--target", cosim(), "--allow-destructive",
                        "--yes"]) == 0


@pytest.mark.slow
def test_a_mutant_found_the_run_goes_on_to_its_end(capsys):
    # seed 0 shrinks a finding through an idiom with a restart (J, then its wait): the
    # co-simulator lives on between sequences, so a frame sent into the restart would
    # leave it silent for the guard and end the run
    status = diff_main(["--target", cosim("--mutant", "velocity-ignored"), "--profile",
                        "GVE84-100", "--allow-destructive", "--yes", "--examples", "2000",
                        "--seed", "0", "--no-reports"])
    said = capsys.readouterr()
    out = said.out + said.err
    assert status == 1, out
    assert "FAIL        10.cmd.exchange-velocity" in out
    assert "not responding" not in out
    assert "\n2000 sequences, " in out, out


#: a few mutants of other kinds for the default run (every mutant: slow)
FEW = ["lower-case-command", "velocity-ignored"]


def _probes_through_a_co_simulator(mutant: str, *, ahead: bool) -> list[tuple]:
    """The findings of the probes through a co-simulated mutant (its rule and kind, and
    the steps shrunk to), with frames told ahead or one exchange a frame."""
    profile = PROFILE.get(mutant, "GVE84-100")
    spec = "exec:" + shlex.join([sys.executable, "-m", "emulator", "--model", profile,
                                 "--cosim", "--mutant", mutant])
    target = parse_target(spec, profile=profile, allow_destructive=True, max_travel=65535,
                          strict=mutant in WITHIN_PLACEMENT)
    target.preflight()
    try:
        p = Pair(Side(target, target.begin()), Side(parse_target(f"emu:{profile}")),
                 target.profile)
        p.ahead = ahead
        budget = Budget(examples=len(probes(p.profile, EVERYTHING)))
        try:
            found = search(p, EVERYTHING, budget)
        except KnownStateLost as lost:
            # the unit left where the manual's rules cannot bring it back: the search
            # ends there, the findings kept, the known state's broken rule named
            assert target.session.failures, lost
            found = lost.findings
    finally:
        target.session.finish()
        target.close()
    return [(f.disagreement.rule, f.disagreement.kind, [str(s) for s in f.steps])
            for f in found]


def _found_as_in_process(mutant: str) -> None:
    ahead = _probes_through_a_co_simulator(mutant, ahead=True)
    assert any(in_area(rule, mutant) for rule, _, _ in ahead), (mutant, ahead)
    # each sequence begins at the power-on: what one left running (the frames told after
    # its disagreement too) never shows in the next
    assert ahead == _probes_through_a_co_simulator(mutant, ahead=False)


@pytest.mark.parametrize("mutant", FEW)
def test_through_a_co_simulator_the_probes_find_a_mutant_told_ahead_as_not(mutant):
    """As in process (tests/conformance/diff/test_engine.py), the probes name a rule of
    the mutant's area; told ahead, they find what they find one exchange a frame."""
    _found_as_in_process(mutant)


@pytest.mark.slow
@pytest.mark.parametrize("mutant", ON_THE_WIRE)
def test_through_a_co_simulator_the_probes_find_every_mutant(mutant):
    _found_as_in_process(mutant)


#: the mutants of motion (their area 10.2); a few of them in the default run
MOTION = sorted(m for m, (area, _) in mutants().items() if area.startswith("10.2"))
MOTION_FEW = {"velocity-ignored", "junction-stops", "short-vector-ignored"}


@pytest.mark.parametrize("mutant", [m if m in MOTION_FEW else
                                    pytest.param(m, marks=pytest.mark.slow) for m in MOTION])
def test_without_allow_destructive_a_motion_mutant_is_searched_to_the_budget(mutant):
    """Each sequence begins at the co-simulator's power-on: no held KEEP or move left by
    the one before stops the search for want of `J` (--allow-destructive), whatever the
    seed; every sequence counted sent frames, so the search runs its whole budget or
    finds the mutant."""
    target = parse_target(cosim("--mutant", mutant), profile="GVE84-100")
    target.preflight()
    p = Pair(Side(target, target.begin()), Side(parse_target("emu:GVE84-100")),
             target.profile)
    target.session.guard.motion_confirmed = True
    try:
        for seed in range(10):
            budget = Budget(examples=12)
            found = search(p, Options(destructive=False, rig=True), budget, seed=seed,
                           with_probes=False, stop_after=1)
            assert found or budget.used == 12, (seed, budget.used)
            assert budget.frames >= budget.used
    finally:
        target.session.finish()
        target.close()
    assert target.session.failures == []


def test_a_power_on_that_leaves_the_checksum_mode_on_is_found_and_named():
    """A co-simulator whose power-on leaves the checksum mode on (spec 9 [M]: off): once a
    sequence has turned it on, the next sequences' first answers differ from the fresh
    reference's, and diff names the reset state's rule; the clean emulator's power-on
    turns it off and agrees."""
    wrapper = Path(__file__).with_name("power_on_keeps_checksums.py")
    leaves = "exec:" + shlex.join([sys.executable, str(wrapper), "--model", "GVE84-100",
                                   "--cosim"])
    for spec, findings in ((leaves, True), (cosim(), False)):
        p = pair(spec)
        try:
            assert p.run([Step(FRAME, body="%+")]).disagreement is None
            found = search(p, Options(destructive=True, rig=True), Budget(examples=10),
                           with_probes=False)
        finally:
            p.target.session.finish()
            p.target.target.close()
        assert bool(found) == findings
        assert all(f.disagreement.rule == "9.reset.state" and f.disagreement.verdict == FAIL
                   and "summing-after-power-on" in f.disagreement.context for f in found)


@pytest.mark.parametrize("mutant", ["lower-case-command", "packet-count-ignored",
                                    "inta-bit-missing"])
def test_a_kept_power_on_restored_finds_the_same_with_fewer_commands(mutant):
    """A co-simulator that keeps a state (`snapshot`, docs/cosim.md): each sequence begins
    from its first power-on restored, and the search finds the same, sending the same
    frames, in fewer commands (one `restore` for `power-on`, the restart's `until` and
    `state`); without the extension it runs as it does."""
    seen = []
    for offered, restores in (((), True), (("--snapshot",), False), (("--snapshot",), True)):
        p = pair(cosim("--mutant", mutant, *offered))
        p.restores = restores
        try:
            # (seed 0 draws a finding of each mutant within its first ten sequences)
            budget = Budget(examples=20)
            found = search(p, EVERYTHING, budget, seed=0, with_probes=False)
            line = p.target.link.port.line
            seen.append(([(f.disagreement.signature, [str(s) for s in f.steps], f.frames)
                          for f in found], budget.used, budget.frames, line.talk.exchanges))
        finally:
            p.target.session.finish()
            p.target.target.close()
    (without, *_, sent), (plain, *_, plain_sent), (kept, *_, fewer) = seen
    assert without and without == plain == kept
    assert seen[0][1:3] == seen[1][1:3] == seen[2][1:3]
    assert sent == plain_sent and fewer < sent - 3 * seen[0][1]


def test_both_sides_await_an_unanswered_w_alike_and_run_on_from_the_same_instant():
    # a W in a packet goes unanswered; the co-simulator's guard (an envelope) and the
    # reference's (none) estimate its run differently, yet both listen as long
    p = pair(cosim())
    p.ahead = False
    steps = [Step(FRAME, body="*S", answer=False), Step(FRAME, body="WX,1,900,1,900"),
             Step(FRAME, body="P")]
    try:
        out = p.run(steps)
        assert out.disagreement is None and not out.ended, out.disagreement
        w = out.records[1]
        assert w.target.answer == w.reference.answer == b""
        assert w.target.received_at - w.target.sent_at == \
            w.reference.received_at - w.reference.sent_at
    finally:
        p.target.session.finish()
        p.target.target.close()


def test_a_repeat_with_a_bad_checksum_then_a_packet_is_no_silence():
    """`>` with a wrong checksum is answered `0` in one line on both sides (no history
    since the reset, spec 8): an answer, not bytes that are none; the packet's start and
    members after it are answered by nothing (spec 7): no silence either."""
    p = pair(cosim())
    p.ahead = False
    steps = [Step(FRAME, body=">", checksum="bad", lines=2),
             Step(FRAME, body="*S", answer=False), Step(FRAME, body="B100000"),
             Step(FRAME, body="VL312,3588,131679"), Step(FRAME, body="C86,0,196")]
    try:
        for _ in range(2):
            out = p.run(steps)
            assert out.disagreement is None and not out.ended, out.ended
    finally:
        p.target.session.finish()
        p.target.target.close()
