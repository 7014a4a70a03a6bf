"""A co-simulator told a sequence's frames ahead (conformance/diff/told.py): the same
sequence runs as it does one exchange a frame — the same bytes at the same instants,
the same answers, the same disagreement — in fewer exchanges; frames told that the
sequence did not reach are sent all the same and booked by the guard; and where the
target's answers drift from the reference's instants the sequence is run again frame by
frame."""

from __future__ import annotations

import contextlib
import shlex
import sys
from collections.abc import Iterator

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import conformance.diff.told as told_module
from conformance.diff.engine import ExampleRun, Pair
from conformance.diff.grammar import Options, sequences
from conformance.diff.index_base import QUERIES
from conformance.diff.labels import command_of
from conformance.diff.sides import Side
from conformance.diff.start import Start
from conformance.diff.steps import FRAME, WAIT, Step
from conformance.diff.timing import Timing
from conformance.link.virtual import line_of
from conformance.targets import parse_target
from conformance.targets.session import RealSession
from gve_fixtures.profile import load_profile


def cosim(*options: str) -> str:
    return "exec:" + shlex.join([sys.executable, "-m", "emulator", "--model", "GVE84-100",
                                 "--cosim", *options])


@contextlib.contextmanager
def mutant_pair(mutant: str) -> Iterator[Pair]:
    """A co-simulated mutant against the reference, its motion confirmed (nothing waits
    for the guard's first look at the axes), finished and closed after."""
    target = parse_target(cosim("--mutant", mutant), profile="GVE84-100",
                          allow_destructive=True)
    target.preflight()
    try:
        pair = Pair(Side(target, target.begin()), Side(parse_target("emu:GVE84-100")),
                    target.profile)
        target.session.guard.motion_confirmed = True
        yield pair
    finally:
        target.session.finish()
        target.close()


@pytest.fixture(scope="module")
def pairs():
    """A co-simulated mutant and the clean emulator, each against the reference, with the
    exchanges each sends counted."""
    made, targets = {}, []
    for name, spec in (("mutant", cosim("--mutant", "velocity-ignored")), ("clean", cosim())):
        # the widest envelope: the guard's bookkeeping of earlier runs (a unit that lives
        # on) decides no refusal that would make two runs of one sequence differ
        target = parse_target(spec, profile="GVE84-100", allow_destructive=True,
                              max_travel=65535)
        target.preflight()
        targets.append(target)
        pair = Pair(Side(target, target.begin()), Side(parse_target("emu:GVE84-100")),
                    target.profile)
        made[name] = pair
    yield made
    for target in targets:
        target.session.finish()
        target.close()


def counted(pair: Pair) -> list[str]:
    """The writes to the pair's co-simulator from now on: each the first words of its
    commands, joined by + where several go in one write (commands sent ahead)."""
    if pair.target.link is None:
        pair.run([])
    program = line_of(pair.target.link.port).program
    sent: list[str] = []
    send = program.send
    program.send = lambda text: sent.append(
        "+".join(line.split()[0] for line in text.splitlines())) or send(text)
    return sent


def outcome(run: ExampleRun) -> tuple:
    """What a run showed: each exchange on both sides (its bytes, how long its answer
    took, how long after the exchange before it it began), where it disagreed, what was
    refused and why it ended. The unit's index lives on between runs: an answer to a
    read of it is taken by its code alone (its digits, and so how long it took and
    where the frame after it began on each side, are not the same in every run)."""
    return [_sides(r, prev) for prev, r in zip([None, *run.records[:-1]], run.records,
                                               strict=True)], \
        run.disagreement and (run.disagreement.index, run.disagreement.rule,
                              run.disagreement.kind), run.refused, run.ended, run.frames


def _sides(rec, prev) -> tuple:
    def seen(trip, before):
        if trip is None:
            return None
        index = command_of(rec.step.body) in QUERIES and trip.response is not None
        took = None if index else trip.received_at - trip.sent_at
        after = prev is not None and command_of(prev.step.body) in QUERIES
        gap = None if after or before is None else trip.sent_at - before.received_at
        return (trip.response.code if index else trip.answer, took, gap)
    return (rec.step, rec.target and rec.target.sent,
            seen(rec.target, prev and prev.target), seen(rec.reference, prev and prev.reference))


def both(pair: Pair, steps: list[Step]) -> tuple[ExampleRun, ExampleRun]:
    pair.ahead = True
    ahead = pair.run(steps)
    pair.ahead = False
    try:
        return ahead, pair.run(steps)
    finally:
        pair.ahead = True


@given(data=st.data())
@settings(max_examples=25, deadline=None, derandomize=True,
          suppress_health_check=list(HealthCheck))
@pytest.mark.parametrize("name", ["mutant", "clean"])
def test_a_sequence_told_ahead_runs_as_it_does_frame_by_frame(pairs, name, data):
    pair = pairs[name]
    steps = data.draw(sequences(load_profile("GVE84-100"), Options(destructive=True, rig=True)))
    ahead, single = both(pair, steps)
    assert outcome(ahead) == outcome(single)


def test_frames_told_ahead_take_fewer_exchanges(pairs, monkeypatch):
    pair = pairs["clean"]
    steps = [Step(FRAME, body=body) for body in
             ("V400", "SR0", "L100,0,0", "SR6", "C10,0,0", "C10,0,0", "?", "F")]
    sent = counted(pair)
    begin = Pair._begin

    def begun(self, out):            # the sequence's exchanges only, not the known state's
        try:
            return begin(self, out)
        finally:
            sent.clear()

    monkeypatch.setattr(Pair, "_begin", begun)
    pair.ahead = True
    pair.run(steps)
    told = list(sent)
    pair.ahead = False
    try:
        pair.run(steps)
    finally:
        pair.ahead = True
    # and after the sequence, in both, what the rig sees (rigstate.py)
    assert sent == ["tx"] * len(steps) + ["state"]
    # told ahead: the frames in one batch, the rig's read after them in the same write
    assert told == ["batch+state"], told


def test_frames_told_after_a_disagreement_are_sent_and_booked(pairs):
    # the mutant answers V0 (out of range) 4, not 5: as soon as the reference, so the
    # frames told after it run
    with mutant_pair("range-error-code") as pair:
        guard = pair.target.target.session.guard
        steps = [Step(FRAME, body=body) for body in ("V0", "C120,0,0", "C120,0,0")]
        run = pair.run(steps)
        assert run.disagreement is not None and run.disagreement.index == 0
        assert len(run.records) == 1, "the sequence stops at its disagreement"
        # the two vectors told with it ran on the simulator: the guard counts them
        assert guard.envelope.seen[0].hi >= 240 * guard.scale
        wire = b"".join(r.data for r in pair.target.link.log)
        assert wire.count(b"!0C120,0,0\r") == 2
        pair.ahead = False
        before = guard.envelope.seen[0].hi
        pair.run(steps)
        assert b"".join(r.data for r in pair.target.link.log).count(b"C120") == 0
        assert guard.envelope.seen[0].hi == before


def test_a_target_drifting_from_the_frames_told_is_run_again_frame_by_frame(pairs,
                                                                             monkeypatch):
    # begun from the known state (not power-on), the co-simulator's index is not the
    # fresh reference's: `@` answered alike (counted from each side's start) in more
    # digits, so the frames told after it begin later on the target than on the
    # reference (`@` ends what is told ahead; here it does not)
    monkeypatch.setattr(told_module, "ENDS", frozenset({"%", "J"}))
    monkeypatch.setattr(RealSession, "powers_on", property(lambda self: False))
    pair = pairs["clean"]
    redone = []
    real_run = Pair._run

    def run(self, steps, *, ahead):
        redone.append(ahead)
        return real_run(self, steps, ahead=ahead)

    monkeypatch.setattr(Pair, "_run", run)
    steps = [Step(FRAME, body=body) for body in ("@", "SR0", "SR0", "@")]
    ahead = pair.run(steps)
    assert redone == [True, False], "drifted, and run again frame by frame"
    pair.ahead = False
    try:
        single = pair.run(steps)
    finally:
        pair.ahead = True
    assert outcome(ahead) == outcome(single)
    assert ahead.disagreement is None and not ahead.ended


def test_a_target_answering_later_than_the_reference_ends_the_comparison_there(pairs):
    # the mutant reads a lower-case command as its upper case and answers it at length,
    # where the reference refuses it at once. The frames were told before the reference
    # ran them: the simulator ran those after it too, and they go out as told, uncompared,
    # once each, so that the guard books the motion they made
    with mutant_pair("lower-case-command") as pair:
        run = pair.run([Step(FRAME, body=body) for body in ("sr0", "C120,0,0", "C120,0,0")])
        assert run.disagreement is not None and run.disagreement.index == 0
        assert len(run.records) == 1
        sent = b"".join(r.data for r in pair.target.link.log)
        assert sent.count(b"!0C120,0,0\r0\r") == 2
        assert pair.target.target.session.guard.envelope.seen[0].hi == 240


def test_the_reference_begins_while_the_co_simulator_runs_the_known_state(pairs,
                                                                          monkeypatch):
    """The reference's known state and prelude are done while the target's known-state
    frames told ahead are on the simulator's line (their reply not read yet), and the
    sequence then runs as it does with the two done one after the other."""
    monkeypatch.setattr(RealSession, "powers_on", property(lambda self: False))
    pair = pairs["clean"]
    steps = [Step(FRAME, body=body) for body in ("V400", "L100,0,0", "SR6", "@", "PF")]
    pair.run(steps)                        # the EEPROM as found read: nothing waits for it
    begin_reference = Start.begin_reference
    seen: list[bool] = []

    def begins(self):
        seen.append(line_of(self.target.link.port)._told is not None)
        begin_reference(self)

    monkeypatch.setattr(Start, "begin_reference", begins)
    overlapped = pair.run(steps)
    monkeypatch.setattr(Start, "eeprom_known", lambda self: False)
    after = pair.run(steps)
    assert seen == [True, False]
    assert outcome(overlapped) == outcome(after)
    assert overlapped.disagreement is None and overlapped.frames == len(steps)


def test_the_reference_runs_the_frames_told_while_the_co_simulator_does(pairs, monkeypatch):
    """A batch is told before the reference runs its frames: each runs on the reference
    while the simulator's reply is unread; a wait's `until`s likewise go out before the
    reference waits. The sequence runs as it does frame by frame."""
    pair = pairs["clean"]
    steps = [Step(FRAME, body=body) for body in ("V400", "SR0", "L100,0,0", "SR6")]
    steps += [Step(WAIT, seconds=1.5), *(Step(FRAME, body=b) for b in ("SR6", "F"))]
    pending: list[tuple[str, bool]] = []
    refer, follow = Pair._refer, Timing._follow

    def referred(self, step, data):
        pending.append((step.body, line_of(self.target.link.port)._told is not None))
        return refer(self, step, data)

    def followed(self, instant):
        pending.append(("wait", bool(line_of(self.target.link.port).talk.ahead)))
        follow(self, instant)

    monkeypatch.setattr(Pair, "_refer", referred)
    monkeypatch.setattr(Timing, "_follow", followed)
    ahead, single = both(pair, steps)
    told = pending[:pending.index(("wait", True)) + 1]
    assert told == [("V400", True), ("SR0", True), ("L100,0,0", True), ("SR6", True),
                    ("wait", True)], told
    assert outcome(ahead) == outcome(single)
    assert ahead.disagreement is None and ahead.frames == 6


def test_a_run_cut_short_while_the_reference_runs_the_frames_told_books_them(monkeypatch):
    """Ctrl-C lands while the reference runs a batch the simulator was told: the guard
    books every frame of it as though run (it may have been), and the line's next use
    reads the simulator's reply first."""
    with mutant_pair("range-error-code") as pair:
        guard = pair.target.target.session.guard
        refer, calls = Pair._refer, []

        def cut(self, step, data):
            calls.append(step.body)
            if len(calls) == 2:
                raise KeyboardInterrupt
            return refer(self, step, data)

        monkeypatch.setattr(Pair, "_refer", cut)
        steps = [Step(FRAME, body=body) for body in ("C120,0,0", "C120,0,0", "SR6")]
        with pytest.raises(KeyboardInterrupt):
            pair.run(steps)
        assert line_of(pair.target.link.port)._told is not None, "told, reply not read"
        assert guard.envelope.reach()[0].hi >= 240 * guard.scale
        monkeypatch.setattr(Pair, "_refer", refer)
        assert pair.target.link.send("SR6") is not None      # the reply read, then SR6
