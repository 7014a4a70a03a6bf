"""The known state a real unit's session sets before each case proves itself and relies
on the manuals' rules only: stopped and read back at rest, the counters read back at 0; a
`K` a case left given back with its `R`, never a second `K`; a step the unit refuses or
that does not do what its rule says is a FAIL of that rule, once, and the run goes on
where it safely can; a unit it cannot bring to rest makes the case COULD-NOT-TEST naming
what was left. The unit: the emulator in process in virtual time behind a ``serial:``
target (tests/conformance/cases/used.py), some of its frames changed on the way."""

from __future__ import annotations

import shlex
import sys

import pytest

from conformance.known_state.way_back import WayBack
from conformance.run.runner import run
from conformance.run.selection import select
from conformance.targets import parse_target
from conformance.verdicts.verdict import COULD_NOT_TEST, ERROR, FAIL, PASS
from gve_fixtures.profile import load_profile
from tests.conformance.cases.used import UsedUnit, used_unit
from tests.conformance.safety.units import Recorder

#: cases that send no D of their own and leave a halted queue or a KEEP behind
CASES = ["5.errors.ok", "10.3.flags.f-command", "10.5.keep.single-l", "10.5.keep.saves-st6",
         "11.golden.g4a-line-idle", "10.5.machine.keep-restore"]


class Rewritten(Recorder):
    """The unit's port with some frames changed on their way to it (a unit that does
    otherwise than its answer says); ``frames`` records what reached the unit."""

    def __init__(self, port, frames: dict[bytes, bytes]) -> None:
        super().__init__(port)
        self._rewrite = frames

    def write(self, data: bytes) -> int:
        return super().write(self._rewrite.get(data, data))


def unit(profile: str = "GVE84-100", frames: dict[bytes, bytes] | None = None, *,
         allow_destructive: bool = False) -> UsedUnit:
    u = used_unit(profile, allow_destructive=allow_destructive, max_travel=4000)
    u.port = Rewritten(u.port, frames or {})
    return u


def frames_sent(u: UsedUnit) -> list[bytes]:
    return u.port.frames


def test_the_known_state_takes_no_second_k_and_gives_back_a_k_left_with_its_r():
    u = unit()
    result = run([u], select(CASES))
    assert {r.id: r.verdict for r in result.results} == dict.fromkeys(
        [c.id for c in select(CASES)], PASS)
    sent = frames_sent(u)
    # K only in the cases; every R either the cases' or the one after single-l's K
    keeps = sent.count(b"!0K\r")
    assert keeps and sent.count(b"!0R\r") <= keeps + 1
    assert result.problems == []


def test_a_reading_refusing_a_second_k_runs_the_k_and_r_cases_and_machine_with_no_fail():
    reading = used_unit("GVE84-100", max_travel=4000, readings=("second-keep-refused",))
    result = run([reading], select(["10.5.*", "11.golden.g6*"]))
    assert [(r.id, r.notes) for r in result.results if r.verdict in (FAIL, ERROR)] == []
    assert result.problems == []


@pytest.mark.parametrize("answered", [b"!0SR0\r", b"!0Z\r"])   # D answered 0 / refused (3)
def test_a_d_that_does_not_delete_is_a_fail_of_its_rule_once_and_the_run_goes_on(answered):
    u = unit(frames={b"!0D\r": answered})
    result = run([u], select(CASES))
    rows = [r for r in result.results if r.id.endswith("known-state.delete")]
    assert len(rows) == 1 and rows[0].verdict == FAIL
    (check,) = rows[0].checks
    assert check["rule"] == "10.4.delete" and "D after H" in check["what"]
    assert "SR6 8,90" in check["observed"]
    # G ran what D left, and every case began at rest: none FAILed, none could not test
    cases = [r for r in result.results if r is not rows[0]]
    assert {r.verdict for r in cases} == {PASS}, [(r.id, r.notes) for r in cases]


def test_a_unit_the_known_state_cannot_bring_to_rest_is_could_not_test_naming_what_was_left():
    # neither D nor G acts, and J is not allowed: the halted queue stays
    u = unit(frames={b"!0D\r": b"!0SR0\r", b"!0G\r": b"!0SR1\r"})
    result = run([u], select(["10.5.keep.saves-st6", "5.errors.ok", "10.3.flags.f-command"]))
    verdicts = {r.id: r.verdict for r in result.results}
    assert verdicts["10.4.known-state.delete"] == FAIL
    # the first H already leaves INTA, which nothing then clears
    for case in ("10.5.keep.saves-st6", "5.errors.ok", "10.3.flags.f-command"):
        (note,) = [r.notes[0] for r in result.results if r.id == case]
        assert verdicts[case] == COULD_NOT_TEST
        assert "not at rest after the known state: SR6 reads 8,D0" in note
        assert "(RUN, INTA)" in note


def test_with_destructive_commands_allowed_j_brings_it_to_rest():
    u = unit(frames={b"!0D\r": b"!0SR0\r", b"!0G\r": b"!0SR1\r"}, allow_destructive=True)
    result = run([u], select(["10.5.keep.saves-st6", "5.errors.ok", "10.3.flags.f-command"]))
    verdicts = {r.id: r.verdict for r in result.results}
    assert verdicts.pop("10.4.known-state.delete") == FAIL
    assert set(verdicts.values()) == {PASS}
    assert b"!0J\r" in frames_sent(u)


@pytest.mark.parametrize(("profile", "then"), [("GVE84-100", PASS), ("GVE54", COULD_NOT_TEST)])
def test_an_n_that_does_not_zero_is_a_fail_of_its_rule_and_n_axis_stands_in(profile, then):
    u = unit(profile, frames={b"!0N\r": b"!0SR0\r"})
    physical = u.state()["physical"]
    result = run([u], select(["5.errors.ok", "10.3.flags.f-command"]))
    verdicts = {r.id: r.verdict for r in result.results}
    assert verdicts.pop("10.known-state.zero") == FAIL
    assert set(verdicts.values()) == {then}
    # a counter that kept its value is not taken for axes that moved: none went back
    # from where they never went
    assert u.state()["physical"] == physical
    if then == COULD_NOT_TEST:                    # the GVE54 has no N<axis>
        assert all("could not be zeroed" in r.notes[0] for r in result.results
                   if r.verdict == COULD_NOT_TEST)


@pytest.mark.parametrize("mutant", ["delete-refused", "delete-ignored"])
def test_the_d_mutants_through_a_session_fail_d_not_a_wall_of_could_not_test(mutant):
    command = [sys.executable, "-m", "emulator", "--model", "GVE84-100", "--cosim",
               "--mutant", mutant]
    target = parse_target("exec:" + shlex.join(command), profile="GVE84-100",
                          allow_destructive=True, max_travel=10_000)
    target.preflight()
    result = run([target], select(["5.*", "10.1.*", "10.3.*"]))
    verdicts = [r.verdict for r in result.results]
    (row,) = [r for r in result.results if r.id == "10.4.known-state.delete"]
    assert row.verdict == FAIL and row.checks[0]["rule"] == "10.4.delete"
    assert ERROR not in verdicts
    # every case began at rest: those that cannot test are only those that send D
    # themselves as a setup step
    lost = [(r.id, r.notes[0]) for r in result.results if r.verdict == COULD_NOT_TEST]
    assert all("setup D answered" in note for _, note in lost), lost
    assert verdicts.count(PASS) > 20


@pytest.mark.parametrize("destructive", [False, True])
def test_a_k_whose_save_the_envelope_cannot_take_back_is_cleared_by_j_or_said(destructive):
    """A K that keeps what is left of 990 steps (halted after about 250, read there),
    then X 700 on: the save's run would end near 1690, beyond an envelope of 1000, so
    the known state does not send R; J clears the save where destructive commands are
    allowed, else the unit is said not to be in the known state."""
    u = used_unit("GVE84-100", max_travel=1000, allow_destructive=destructive)
    u.port = Rewritten(u.port, {})
    session = u.begin()
    link = session.open_link()
    for body in ("V500", "C330,0,0", "C330,0,0", "C330,0,0"):
        assert link.send(body).ok
    link.wait(0.5)
    assert link.send("H").inta
    assert link.send("K").ok
    assert link.send("PF").ok
    assert link.send("V5000").ok and link.send("L700,0,0").ok
    link.wait(1.0)
    assert link.send("SR6").raw == b"0,00\r"
    assert not session.guard.fits("R")
    result = run([u], select(["11.golden.g4f-status-read"]))
    assert b"!0R\r" not in frames_sent(u)
    (r,) = result.results
    if destructive:
        assert r.verdict == PASS and b"!0J\r" in frames_sent(u)
    else:
        assert r.verdict == COULD_NOT_TEST and "a KEEP the last case left is still held" in \
            r.notes[0]
        assert any("KEEP" in p for p in result.problems), result.problems


def test_a_k_whose_save_runs_where_the_axes_may_already_be_is_given_back_with_r():
    """single-l leaves a K holding what is left of a 990-step queue and moves X 10 after
    it: the save's run goes where the queue could still go, moved by those 10 (10..1000),
    inside an envelope of 1000, so the known state gives it back with R."""
    u = used_unit("GVE84-100", max_travel=1000, allow_destructive=False)
    u.port = Rewritten(u.port, {})
    result = run([u], select(["10.5.keep.single-l", "11.golden.g4f-status-read"]))
    assert {r.id: r.verdict for r in result.results} == {
        "10.5.keep.single-l": PASS, "11.golden.g4f-status-read": PASS}
    assert b"!0R\r" in frames_sent(u) and b"!0J\r" not in frames_sent(u)
    assert result.problems == []


def _known_states(mutant: str, frames: list[str], seconds: float) -> tuple[list, list]:
    """The known-state failures of a used unit with ``mutant`` before and after
    ``frames`` (then ``seconds``), and the known state reached all the same."""
    u = used_unit("GVE84-100", allow_destructive=True, max_travel=4000, mutant=mutant)
    session = u.begin()
    link = session.open_link()
    first = session.take_failures()
    assert all(r is not None for r in link.send_each(frames))
    link.wait(seconds)
    link = session.open_link()
    after = session.take_failures()
    assert link.send("SR6").raw == b"0,00\r" and link.send("PF").raw == b"0,0,0,0\r"
    session.finish()
    return first, after


@pytest.mark.parametrize(("mutant", "frames", "seconds", "rule"), [
    # W answered at once, its run still going when H is answered and D refused as busy
    ("reference-answers-early", ["WX,-100,1000,50,1000"], 0, "10.cmd.reference"),
    # H answered while its ramp still runs
    ("halt-answers-early", ["V5000", "L3000,0,0"], 0.3, "10.4.halt.ramp"),
])
def test_a_d_refused_as_busy_after_h_names_what_still_moved_the_axes(mutant, frames, seconds,
                                                                      rule):
    # moving after H's answer (PF read twice): the frame that answers only once the axes
    # stopped did not, the W that last set them moving or else H
    first, (failure,) = _known_states(mutant, frames, seconds)
    assert first == []
    assert failure.rule == rule, failure
    assert "D F" in failure.observed and " then " in failure.observed
    # the frames that led there: the sequence's, then the known state's two PF reads
    assert any(f"> !0{frames[-1]}" in line for line in failure.led_there)
    assert sum("> !0PF" in line for line in failure.led_there) >= 2


def test_a_d_refused_as_busy_with_the_axes_at_rest_is_ds_own_rule():
    (failure,), after = _known_states("delete-refused", ["L300,0,0"], 0)
    assert failure.rule == "10.4.delete" and "D F" in failure.observed
    # sent again once SR6 showed RUN clear or the longest T was over: refused all the same
    read, again = failure.observed.split("PF ")[1].split(", D again ")
    first, then = read.split(" then ")
    assert first == then and again == "F"
    assert after == []                           # each rule once a run


@pytest.mark.parametrize("profile", ["GVE84-100", "GVE54"])
def test_a_d_refused_while_a_dwell_outlives_h_is_sent_again_once_st6_shows_it_over(profile):
    """A reader counting the T dwell after a vector as running, which H does not end:
    the known state's D is refused with 7 (RUN with INTA, as halted vectors show), then
    sent again once SR6 shows RUN clear, and taken: no step failed, the unit at rest."""
    u = used_unit(profile, allow_destructive=True, max_travel=4000,
                  readings=("dwell-outlives-halt",))
    u.port = Rewritten(u.port, {})
    session = u.begin()
    link = session.open_link()
    assert session.take_failures() == []
    longest = load_profile(profile).range("T").hi
    assert link.send(f"T{longest}").ok and link.send("L0,0,0").ok
    before = len(frames_sent(u))
    link = session.open_link()                  # the known state: H within the dwell
    assert session.take_failures() == []
    assert link.send("SR6").raw == b"0,00\r"
    session.finish()
    sent = frames_sent(u)[before:]
    halt = sent.index(b"!0H\r")
    # D refused in the dwell, SR6 read until RUN cleared, D again
    assert sent[halt:].count(b"!0D\r") >= 2 and b"!0SR6\r" in sent[halt:]


def test_an_h_refused_is_a_fail_of_its_rule_and_the_stop_goes_on():
    u = unit(frames={b"!0H\r": b"!0Z\r"})            # answered 3 (unknown)
    result = run([u], select(["5.errors.ok", "10.3.flags.f-command"]))
    verdicts = {r.id: r.verdict for r in result.results}
    assert verdicts.pop("10.known-state.halt") == FAIL
    assert set(verdicts.values()) == {PASS}


@pytest.mark.parametrize(("summed", "rule"), [(True, "6.checksum.sum"),
                                              (False, "10.cmd.halt-answer")])
def test_an_h_refused_with_4_in_either_framing_in_checksum_mode_fails_the_checksum_sum(
        summed, rule):
    # H has no parameter: refused with 4 (a bad or missing checksum) summed as the manual
    # sums it and plain alike, by a unit that took %+ (and never gets the case's %-), it
    # breaks the checksum's framing; with checksums off, H's own rule
    refused = b"!0?1\r"                              # answered 4
    frames = {b"!0H\r": refused, b"!0H,C5\r": refused}
    if summed:
        frames[b"!0%-,CF\r"] = refused
    u = unit(frames=frames)
    result = run([u], select(["6.checksum.mode-on-off", "5.errors.ok"]))
    rows = [r for r in result.results if r.id.endswith("known-state.halt")]
    assert len(rows) == 1 and rows[0].verdict == FAIL
    assert rows[0].checks[0]["rule"] == rule and rows[0].checks[0]["observed"].startswith("H 4")
    # the frames that led there are its transcript: the known state's own, H first
    assert any("> !0H" in line for line in rows[0].wire_log), rows[0].wire_log


def test_a_return_move_still_running_after_its_wait_idiom_fails_that_rule_and_is_awaited(
        monkeypatch):
    # the way back polled at once, as for a unit whose ramps outlast the reset
    # acceleration's: the first L0,0,0 then goes out while the axes still move
    monkeypatch.setattr(WayBack, "_watch", lambda self, link, seconds: None)
    command = [sys.executable, "-m", "emulator", "--model", "GVE84-100", "--cosim",
               "--mutant", "line-while-busy"]          # L0,0,0 answered 0 while moving
    target = parse_target("exec:" + shlex.join(command), profile="GVE84-100",
                          allow_destructive=True, max_travel=10_000)
    target.preflight()
    result = run([target], select(["10.1.*", "10.2.*"]))
    (row,) = [r for r in result.results if r.id == "10.1.known-state.return-move"]
    assert row.verdict == FAIL and row.checks[0]["rule"] == "10.1.queue.wait-idiom"
    assert "SR6 0,40" in row.checks[0]["observed"]
    # the case before it, whose motion the return move undid, heads the transcript
    assert "# the known state" in row.wire_log and row.wire_log[0] != "# the known state"
    # the move's end awaited: no case lost to a unit not at rest
    assert not [r.id for r in result.results if r.verdict == COULD_NOT_TEST
                and "not at rest" in " ".join(r.notes)]
    assert ERROR not in [r.verdict for r in result.results]


def test_an_r_refused_at_rest_with_a_k_held_is_still_a_fail_of_its_rule():
    # R answered as an unknown command (3) once the halted vectors are deleted: at rest,
    # with the save of a K the unit took, no reading refuses it
    u = unit(frames={b"!0R\r": b"!0Z\r"}, allow_destructive=True)
    result = run([u], select(["10.5.keep.single-l", "5.errors.ok"]))
    rows = [r for r in result.results if r.id.endswith("known-state.restore")]
    assert len(rows) == 1 and rows[0].verdict == FAIL
    (check,) = rows[0].checks
    assert check["rule"] == "10.5.restore.exact" and check["observed"] == "R 3 at rest"


#: readings of what the known state sends (profile, reading): L0,0,0 holding RUN for its
#: T dwell (N after the return move, N<axis> and EW at the end), that dwell outliving the
#: known state's H (D refused with 7 until it is over), R refused while halted vectors
#: hold RUN (a K a case left, given back after H), M refused likewise (the GVE54's reset
#: frames)
MACHINERY_READINGS = [("GVE84-100", "zero-vector-dwells"), ("GVE54", "zero-vector-dwells"),
                      ("GVE84-100", "dwell-outlives-halt"), ("GVE54", "dwell-outlives-halt"),
                      ("GVE84-100", "restore-refused-while-run"),
                      ("GVE54", "restore-refused-while-run"),
                      ("GVE54", "motor-mode-refused-while-run")]
#: cases that end moving, halted, with a K held, or right after L0,0,0
MACHINERY_CASES = [*CASES, "10.1.*", "10.5.*", "10.7.*", "10.cmd.zero*"]


@pytest.mark.parametrize(("profile", "reading"), MACHINERY_READINGS)
def test_the_known_state_waits_for_run_to_clear_under_every_reading(profile, reading):
    u = used_unit(profile, max_travel=4000, readings=(reading,), allow_destructive=True)
    result = run([u], select(MACHINERY_CASES))
    # nothing of the machinery FAILs, nothing is lost to a unit not brought to rest
    steps = [(r.id, r.checks) for r in result.results if ".known-state." in r.id]
    assert steps == []
    lost = [(r.id, r.notes[:1]) for r in result.results if r.verdict == COULD_NOT_TEST
            and any("known state" in n or "not at rest" in n for n in r.notes)]
    assert lost == []
    # the unit left at rest, as found: nothing moving, counters, EEPROM, status words back
    assert result.problems == []
    state = u.state()
    assert state["status"][6] == "00" and state["queue"] == 0
    report = result.sessions[u.info.spec]
    assert any(line.startswith("axes back where the run began") for line in report["restored"])


def test_the_known_state_sets_the_spindle_off_as_reset_leaves_it():
    # O0,FF need not reset the setting of !7V: a unit may keep the two apart
    u = unit("GVE114-500")
    result = run([u], select(["5.errors.ok", "10.3.flags.f-command"]))
    assert {r.verdict for r in result.results} == {PASS}, [(r.id, r.notes) for r in result.results]
    sent = frames_sent(u)
    spindle_off = [i for i, f in enumerate(sent) if f == b"!7V0\r"]
    assert len(spindle_off) >= 2            # before each case
    assert result.problems == []
