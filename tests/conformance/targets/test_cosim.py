"""exec: targets that co-simulate (docs/cosim.md): the program that prints `cosim 1` runs
in virtual time, the suite driving its clock over the text protocol; the emulator as such
a program answers as in process; and a simulator that breaks the protocol — silence, no
`now`, time going backwards, a byte stamped in the past or the future, a clock that
overshoots or stops short, garbage, an error where the clock was to move, a program that
dies — is the target's FAIL naming what it sent, within a bounded time, never an
ERROR."""

from __future__ import annotations

import shlex
import subprocess
import sys
import time

import pytest

from conformance.run.runner import run
from conformance.run.selection import select
from conformance.targets import TargetError, parse_target
from conformance.targets import cosim as cosim_module
from conformance.verdicts.verdict import COULD_NOT_TEST, ERROR, FAIL, PASS

EMULATOR = [sys.executable, "-m", "emulator", "--cosim"]

#: a co-simulator of a unit that never answers, which breaks the protocol in one way
#: (argv[1]) at its second tx or until; before that it keeps the clock as it should
BROKEN = r"""
import sys, time
mode, moves, now = sys.argv[1], 0, 0
print("cosim 1", flush=True)
for line in sys.stdin:
    w = line.split()
    if not w:
        continue
    if w[0] == "quit":
        break
    if mode == "silence":
        continue
    if w[0] not in ("tx", "until"):
        print("ok" if w[0] == "baud" else "error: no rig", flush=True)
        continue
    start = now
    end = now + (len(w[1]) // 2 * 86806 if w[0] == "tx" else 0)
    goal = int(w[-1]) if len(w) == (3 if w[0] == "tx" else 2) else end
    moves += 1
    if moves < 2 or mode == "none":
        now = goal
        print(f"now {now}", flush=True)
        continue
    if mode == "dies":
        print("the simulator gave up", file=sys.stderr, flush=True)
        sys.exit(3)
    out = {
        "no-now": [f"rx {goal} 310D"],
        "backwards": [f"now {start - 1000}"],
        "past": [f"rx {start} 30", f"now {goal}"],
        "future": [f"rx {goal + 1000} 30", f"now {goal}"],
        "overshoot": [f"now {goal + 1}"],
        "short": [f"now {goal - 1}"],
        "garbage": ["hello there"],
        "digits": [f"now {goal}²"],
        "huge": ["now " + "9" * 5000],
        "escape": ["\x1b]0;title\x07\x1b[2J"],
        "error": ["error: the clock is broken"],
        "after-cr": [f"rx {goal - 2000} 0D", f"rx {goal - 1000} 30", f"now {goal}"],
    }[mode]
    now = goal
    print("\n".join(out), flush=True)
    if mode == "no-now":
        time.sleep(60)
"""

#: what each break's FAIL says
SAYS = {
    "silence": "no reply to 'baud 115200' within",
    "no-now": "and then nothing within",
    "backwards": "time went backwards",
    "past": "a byte in the past",
    "future": "a byte in the future",
    "overshoot": "past the instant",
    "short": "where the clock had to stop",
    "garbage": '"hello there": not rx T HEX or now T',  # quoted as a target's text is
    "error": "it refused",
    "after-cr": "after the CR",
    "dies": 'exited with status 3 (stderr: "the simulator gave up")',
    "digits": "²\": not now T",                   # str.isdigit() takes ², int() does not
    "huge": "99...\": not now T",                 # more digits than int() reads
    "escape": '"\\x1B]0;title\\x07\\x1B[2J": not rx T HEX',   # escaped, not run
}


def broken(mode: str):
    target = parse_target("exec:" + shlex.join([sys.executable, "-c", BROKEN, mode]),
                          profile="GVE84-100")
    target.preflight()
    return target


@pytest.fixture
def quick(monkeypatch):
    monkeypatch.setattr(cosim_module, "REPLY_SECONDS", 0.5)
    monkeypatch.setattr("conformance.targets.program.QUIT_SECONDS", 0.3)
    monkeypatch.setattr("conformance.targets.program.TERM_SECONDS", 0.3)


def test_the_emulator_as_a_co_simulator_runs_in_virtual_time_with_its_rig():
    target = parse_target("exec:" + shlex.join(EMULATOR), profile="GVE84-100",
                          allow_destructive=True)
    target.preflight()
    assert target.info.virtual_time and target.info.has_rig and target.info.kind == "exec"
    cases = ["5.errors.ok", "10.2.measured.cruise-at-v", "10.cmd.output.port",
             "10.3.inputs.physical-across-restart", "11.golden.g7-reset-state"]
    start = time.monotonic()
    result = run([target], select(cases))
    assert {r.id: r.verdict for r in result.results} == {c: PASS for c in cases}, [
        (r.id, r.notes, r.failed_checks) for r in result.results]
    assert time.monotonic() - start < 10, "virtual time: the waits take no wall time"
    assert result.problems == [] and target.program is None
    session = result.sessions[target.info.spec]
    assert session["real"] and session["restored"], "the session's restorations ran"


@pytest.mark.parametrize("strict", [False, True])
def test_the_motion_is_judged_at_the_emulator_s_instants(strict: bool):
    """Every reading as on the embedded emulator: the same instants, the same positions;
    the step placement somebody else's unit may choose is allowed a step (none with
    --strict, for a clone that claims the project's arithmetic)."""
    target = parse_target("exec:" + shlex.join(EMULATOR), profile="GVE84-100", strict=strict)
    target.preflight()
    (r,) = run([target], select(["10.2.measured.cruise-at-v"])).results
    (emu,) = run([parse_target("emu:GVE84-100")], select(["10.2.measured.cruise-at-v"])).results
    readings = [(c["what"], c["observed"], c["expected"]) for c in r.checks
                if " PF at " in c["what"]]
    assert r.verdict == PASS and len(readings) > 3
    band = "" if strict else " (±1 step)"
    assert readings == [(c["what"] + band, c["observed"], c["expected"]) for c in emu.checks
                        if " PF at " in c["what"]]


def test_a_mutant_through_the_protocol_fails_its_case():
    target = parse_target("exec:" + shlex.join([*EMULATOR, "--mutant", "velocity-ignored"]),
                          profile="GVE84-100")
    target.preflight()
    result = run([target], select(["10.2.measured.cruise-at-v"]))
    assert [r.verdict for r in result.results] == [FAIL]


def test_the_envelope_and_the_destructive_guard_apply():
    target = parse_target("exec:" + shlex.join(EMULATOR), profile="GVE84-100")
    target.preflight()
    result = run([target], select(["10.2.measured.max-rate", "11.golden.g9-eeprom-relay"]))
    notes = {r.id: (r.verdict, r.notes) for r in result.results}
    assert notes["10.2.measured.max-rate"][0] == COULD_NOT_TEST
    assert "envelope" in notes["10.2.measured.max-rate"][1][0]
    assert notes["11.golden.g9-eeprom-relay"] == (
        COULD_NOT_TEST, ["destructive: needs --allow-destructive"])


def test_a_protocol_version_the_suite_does_not_speak_is_refused_before_anything():
    target = parse_target("exec:" + shlex.join([sys.executable, "-c", "print('cosim 2')"]),
                          profile="GVE84-100")
    with pytest.raises(TargetError, match="speaks co-simulation version 2; this suite "
                                          "speaks version 1"):
        target.preflight()


def test_a_simulator_that_keeps_the_protocol_but_never_answers_is_not_responding(quick):
    result = run([broken("none")], select(["5.errors.ok", "5.errors.unknown"]))
    first = result.results[0]
    assert first.verdict == FAIL and "frames unanswered" in first.failed_checks[0]["what"]


@pytest.mark.parametrize("mode", sorted(SAYS))
def test_a_simulator_that_breaks_the_protocol_fails_saying_what_it_sent(quick, mode):
    target = broken(mode)
    assert target.info.virtual_time
    start = time.monotonic()
    result = run([target], select(["5.errors.ok", "5.errors.unknown", "6.checksum.*"]))
    took = time.monotonic() - start
    verdicts = [r.verdict for r in result.results]
    assert verdicts[0] == FAIL and set(verdicts[1:]) == {COULD_NOT_TEST}, verdicts
    assert ERROR not in verdicts
    why = result.results[0].failed_checks[0]["what"]
    assert SAYS[mode] in why, why
    assert mode in ("silence", "dies") or "the co-simulator broke the protocol" in why
    assert any("restorations stopped" in p for p in result.problems)
    assert took < 5, f"{took:.1f} s"
    assert target.program is None


def test_the_command_line_says_fail_and_exits_1():
    command = "exec:" + shlex.join([sys.executable, "-c", BROKEN, "garbage"])
    done = subprocess.run([sys.executable, "-m", "conformance", "--target", command,
                           "--profile", "GVE84-100", "--yes", "--no-reports",
                           "--cases", "5.errors.*"], capture_output=True, text=True,
                          timeout=120, stdin=subprocess.DEVNULL)
    assert done.returncode == 1, done.stdout + done.stderr
    assert "FAIL" in done.stdout and '"hello there"' in done.stdout
    assert "Traceback" not in done.stdout + done.stderr


class Interrupting:
    """A channel whose first reply never comes: the wait for it is interrupted."""

    alive = True

    def send(self, text: str) -> bool:
        return True

    def line(self, timeout: float) -> str | None:
        raise KeyboardInterrupt

    def wait(self, seconds: float) -> bool:
        return False

    def ended(self) -> str:
        return ""


def test_an_exchange_cut_off_before_its_reply_leaves_the_line_broken_not_misread():
    line = cosim_module.CosimLine(Interrupting(), 115200)
    line.write(b"!0?\r")
    with pytest.raises(KeyboardInterrupt):
        line.read(100, 1.0, b"\r")
    with pytest.raises(cosim_module.ProtocolBroken, match="was cut off before its reply"):
        line.ask("state")


def test_next_and_run_until_idle_through_the_client():
    target = parse_target("exec:" + shlex.join(EMULATOR), profile="GVE84-100")
    target.preflight()
    try:
        port = target.connect(None)[0]
        line = port.line
        assert line.next_event() is None
        port.write(b"!0V1000\r")
        assert port.read_until(b"\r") == b"0\r"
        port.write(b"!0L3000,0,0\r")
        assert port.read_until(b"\r") == b"0\r"
        assert line.next_event() > line.now
        assert line.run_until_idle() and line.next_event() is None
        assert line.now > 3 * cosim_module.SECOND, "3000 steps at 1000/s"
    finally:
        target.close()


def test_a_simulator_that_does_not_tell_its_next_event_says_so():
    line = cosim_module.CosimLine(Replies(["error: no"]), 115200)
    with pytest.raises(LookupError, match="does not tell its next event"):
        line.next_event()
    assert not line.broken


class Replies(Interrupting):
    """A channel that replies these lines in turn."""

    def __init__(self, replies: list[str]) -> None:
        self.replies = list(replies)

    def line(self, timeout: float) -> str | None:
        return self.replies.pop(0) if self.replies else None


@pytest.mark.parametrize("strict", [False, True])
def test_a_co_simulator_is_graded_as_a_target_other_than_the_reference(strict):
    """Strict (a failed [D] check FAILs) only when the run says --strict: the clock is
    the suite's, the firmware somebody else's."""
    target = parse_target("exec:" + shlex.join(EMULATOR), profile="GVE84-100", strict=strict)
    target.preflight()
    try:
        assert target.info.virtual_time and target.info.strict is strict
    finally:
        target.close()


def test_the_first_line_may_name_the_extensions_it_speaks():
    assert cosim_module.announced("cosim 1 batch") == 1
    assert cosim_module.offered("cosim 1 batch later") == {"batch", "later"}
    assert cosim_module.offered("cosim 1") == frozenset()
    assert cosim_module.offered("/dev/pts/7") == frozenset()


#: frames whose answers come at once, and H, which answers once the axis has stopped
#: (awaited longer than the 1 s one frame of a batch may take: sent on its own, or with
#: `batch-stops` told with 1 s)
FRAMES = ["?", "SW0,00", "D", "V1000", "L500,0,0", "SR6", "PF", "H"]


def _sent(extensions: frozenset[str] = frozenset(), frames: list[str] = FRAMES):
    """The records, answers, clock and commands sent of ``frames`` by Link.send_each on a
    co-simulated emulator, with those of its extensions."""
    from conformance.link.link import Link

    target = parse_target("exec:" + shlex.join(EMULATOR), profile="GVE84-100")
    target.preflight()
    try:
        port, baud, virtual, _ = target.connect(None)
        assert extensions <= port.line.extensions
        port.line.extensions = extensions
        commands = []
        send = port.line.program.send
        port.line.program.send = lambda text: commands.append(text) or send(text)
        link = Link(port, target.session.guard, baud=baud, virtual=virtual)
        target.session.guard.motion_confirmed = True
        answers = link.send_each(frames)
        records = [(r.direction, r.data, r.t) for r in link.log]
        return records, [a and a.raw for a in answers], port.line.now, list(commands)
    finally:
        target.close()


@pytest.mark.parametrize(("extensions", "sent"), [({"batch"}, ["batch", "tx"]),
                                                   ({"batch", "batch-stops"}, ["batch"])])
def test_frames_told_ahead_go_in_one_exchange_and_read_as_one_a_frame(extensions, sent):
    batched, answers, now, commands = _sent(frozenset(extensions))
    single, single_answers, single_now, single_commands = _sent()
    assert (batched, answers, now) == (single, single_answers, single_now)
    assert [c.split()[0] for c in commands] == sent
    assert [c.split()[0] for c in single_commands] == ["tx"] * len(FRAMES)
    assert answers[FRAMES.index("H")] is not None, "H answered once the axis stopped"


def test_a_batch_that_stops_at_a_frame_unanswered_sends_the_rest_as_they_come():
    """`batch-stops`: `*S` (opening a packet) gets no answer; the batch ends there (the
    simulator ran none after it), and the frames after it go one an exchange: the same
    bytes at the same instants."""
    frames = ["SR6", "*S", "SR6", "PF"]
    batched, answers, now, commands = _sent(frozenset({"batch", "batch-stops"}), frames)
    single, single_answers, single_now, _ = _sent(frozenset(), frames)
    assert (batched, answers, now) == (single, single_answers, single_now)
    # the frame after the unanswered *S waits out a packet's watchdog first (until)
    assert [c.split()[0] for c in commands if not c.startswith("until")] == \
        ["batch", "tx", "tx"], commands
    assert answers[0] is not None and answers[1] is None


def test_frames_told_ahead_and_not_sent_as_told_leave_the_clock_on_the_simulator_s():
    target = parse_target("exec:" + shlex.join(EMULATOR), profile="GVE84-100")
    target.preflight()
    try:
        port = target.connect(None)[0]
        line = port.line
        port.timeout = 0.25
        frames = [b"!0V1000\r", b"!0A20\r", b"!0?\r"]
        port.expect([(f, 0.25) for f in frames])
        port.write(frames[0])
        assert port.read_until(b"\r") == b"0\r"
        simulator = line._ahead[-1].now
        port.write(b"!0SR6\r")                    # not what was told: A20 and ? ran
        assert port.read_until(b"\r") == b"0,00\r"
        assert line.now > simulator, "the clock went on from the simulator's"
        port.write(b"!0?\r")
        assert port.read_until(b"\r").startswith(b"0,IP84"), "the line goes on, in step"
        assert not line.broken and not line._ahead
    finally:
        target.close()


def test_only_the_next_frame_told_ahead_is_one_the_simulator_ran_already():
    """A frame told ahead is run before the suite writes it: its write puts nothing on
    the simulator's line (the link holds no signals for it); any other write does."""
    target = parse_target("exec:" + shlex.join(EMULATOR), profile="GVE84-100")
    target.preflight()
    try:
        port = target.connect(None)[0]
        port.timeout = 0.25
        frames = [b"!0SR6\r", b"!0SR0\r"]
        assert not port.ran(frames[0]), "nothing told yet"
        port.expect([(f, 0.25) for f in frames])
        assert port.ran(frames[0]) and not port.ran(frames[1]), "in turn"
        port.write(frames[0])
        assert not port.ran(frames[1]), "its answer not read yet"
        assert port.read_until(b"\r") == b"0,00\r"
        assert port.ran(frames[1]) and not port.ran(b"!0PF\r")
        port.write(b"!0PF\r")                      # not as told: SR0 ran, is dropped
        assert port.read_until(b"\r").startswith(b"0,")
        assert not port.ran(frames[1])
    finally:
        target.close()


def _launched(launch: bool):
    """The answers, clock and commands of three frames written and read on a co-simulated
    emulator, each write launched before its read or not."""
    target = parse_target("exec:" + shlex.join(EMULATOR), profile="GVE84-100")
    target.preflight()
    try:
        port = target.connect(None)[0]
        port.line.extensions = frozenset()
        commands = []
        send = port.line.program.send
        port.line.program.send = lambda text: commands.append(text) or send(text)
        port.timeout, answers = 0.25, []
        for data in (b"!0?\r", b"!0SR0\r", b"!0PF\r"):
            port.write(data)
            if launch:
                port.launch(port.timeout)
                assert port.line._inflight is not None, "sent before the read"
            answers.append(port.read_until(b"\r"))
        return answers, port.line.now, list(commands)
    finally:
        target.close()


def test_a_write_launched_before_its_read_is_the_exchange_the_read_would_send():
    launched = _launched(True)
    assert launched == _launched(False)
    assert [c.split()[0] for c in launched[2]] == ["tx"] * 3 and all(launched[0])


def _waited(data: bytes, seconds: float):
    """The commands, bytes received and clock of a write then a wait of ``seconds`` on a
    co-simulated emulator."""
    target = parse_target("exec:" + shlex.join(EMULATOR), profile="GVE84-100")
    target.preflight()
    try:
        port = target.connect(None)[0]
        commands = []
        send = port.line.program.send
        port.line.program.send = lambda text: commands.append(text) or send(text)
        start = port.line.now
        port.write(data)
        port.line.advance(seconds)
        return [c.split()[0] for c in commands], port.read(port.in_waiting), \
            port.line.now - start
    finally:
        target.close()


def test_a_write_and_the_wait_after_it_go_in_one_exchange():
    # no answer: `tx HEX T` runs the clock to T; an answer stops it at its CR, and the
    # wait goes on from there
    assert _waited(b"!0*S\r", 0.01) == (["tx"], b"", 10_000_000 + 5 * 86806)
    assert _waited(b"!0?\r", 0.05) == (["tx", "until"], b"0,IP84 v3 27.1.2010\r",
                                       50_000_000 + 4 * 86806)


@pytest.mark.parametrize(("second", "ran"), [(b"!0SR0\r", 4), (b"!0*S\r", 2)])
def test_telling_frames_ahead_says_how_many_the_simulator_ran(second, ran):
    # `batch-stops`: the batch ends after a frame that got no answer (*S)
    target = parse_target("exec:" + shlex.join(EMULATOR), profile="GVE84-100")
    target.preflight()
    try:
        port = target.connect(None)[0]
        frames = [b"!0SR6\r", second, b"!0SR6\r", b"!0PF\r"]
        assert port.expect([(f, 0.25) for f in frames]) == ran
        assert len(port.line._ahead) == ran
        assert port.expect([(frames[0], 0.25)]) == 0, "frames told already wait first"
    finally:
        target.close()


def _told_then_sent(later: bool):
    """The answers and clock of frames told ahead (their reply read at once, or left
    for the line's next use) and then written and read, and whether the reply was left
    unread until then."""
    target = parse_target("exec:" + shlex.join(EMULATOR), profile="GVE84-100")
    target.preflight()
    try:
        port = target.connect(None)[0]
        port.timeout = 0.25
        frames = [b"!0SR6\r", b"!0V1000\r", b"!0?\r"]
        told = [(f, 0.25) for f in frames]
        if later:
            assert port.tell(told)
            unread = port.line._told is not None and not port.line._ahead
        else:
            assert port.expect(told) == len(frames)
            unread = False
        answers = []
        for data in frames:
            assert port.ran(data), "run by the simulator when told"
            port.write(data)
            answers.append(port.read_until(b"\r"))
        return answers, port.line.now, unread
    finally:
        target.close()


def test_frames_told_with_their_reply_read_later_are_sent_as_those_read_at_once():
    """A reply left unread while the suite does other work is read, checked, at the
    line's next use: the same answers at the same instants."""
    *later, unread = _told_then_sent(True)
    *at_once, _ = _told_then_sent(False)
    assert unread, "nothing read before the line's next use"
    assert later == at_once and all(later[0])


def _writes(pipeline: bool, act):
    """The writes to a co-simulated emulator (each its commands' first words), and what
    ``act(line)`` gave, with the extension `pipeline` on or off."""
    target = parse_target("exec:" + shlex.join(EMULATOR), profile="GVE84-100")
    target.preflight()
    try:
        line = target.connect(None)[0].line
        assert "pipeline" in line.extensions
        if not pipeline:
            line.extensions = line.extensions - {"pipeline"}
        writes = []
        send = line.program.send
        line.program.send = lambda text: writes.append(
            [c.split()[0] for c in text.splitlines()]) or send(text)
        done = act(line)
        return list(writes), done
    finally:
        target.close()


def _wait_read(line):
    """A `?` written, a wait of 2.5 s over its answer, what came and the clock."""
    start = line.now
    line.write(b"!0?\r")
    line.advance(2.5)
    return line.read(64, 0.0), line.now - start


def test_the_untils_of_a_long_wait_go_in_one_write_where_the_simulator_takes_them():
    one_by_one, seen = _writes(False, _wait_read)
    ahead, seen_ahead = _writes(True, _wait_read)
    # the answer stops the clock at its CR; the 2.5 s from there take three `until`s
    assert seen == seen_ahead == (b"0,IP84 v3 27.1.2010\r", 2_500_000_000 + 4 * 86806)
    assert one_by_one == [["tx"], ["until"], ["until"], ["until"]]
    assert ahead == [["tx"], ["until", "until", "until"]]


def _launched_wait(line):
    """A `?` sent, then a wait of 2.5 s launched (CosimLine.launch_wait) and waited:
    whether it was launched, the replies still unread then, and the clock after."""
    start = line.now
    line.write(b"!0?\r")
    line.read(64, 0.0)                  # the frame goes out: no wait for its answer
    launched = line.launch_wait(2.5)
    unread = len(line.talk.ahead)
    line.advance(2.5)
    return launched, unread, line.read(64, 0.0), line.now - start


def test_a_wait_launched_before_it_is_waited_is_the_same_wait_in_one_write():
    one_by_one, seen = _writes(False, _launched_wait)
    ahead, seen_ahead = _writes(True, _launched_wait)
    # the simulator runs the wait's three `until`s while the suite does other work
    assert seen_ahead[:2] == (True, 3) and seen[:2] == (False, 0)
    assert seen_ahead[2:] == seen[2:] == (b"0,IP84 v3 27.1.2010\r", 4 * 86806 + 2_500_000_000)
    # one by one, the answer's CR stops the first `until` short: one more is sent
    assert one_by_one == [["tx"], ["until"], ["until"], ["until"], ["until"]]
    assert ahead == [["tx"], ["until", "until", "until"]]


def _powered(line, then: str = "state"):
    """A power-on sent ahead with its restart and `state`, taken in turn (or ``then``
    asked first): what it answered and the clock."""
    start = line.now
    told = line.power_on_ahead(2.25, state=True)
    ok = line.ask("power-on")
    line.advance(2.25)
    return told, ok, line.ask(then)[:12], line.now - start


@pytest.mark.parametrize("then", ["state", "next"])
def test_a_power_on_its_restart_and_the_state_after_it_go_in_one_write(then):
    one_by_one, seen = _writes(False, lambda line: _powered(line, then))
    ahead, seen_ahead = _writes(True, lambda line: _powered(line, then))
    assert seen[1:] == seen_ahead[1:] and seen[0] is False and seen_ahead[0] is True
    assert seen[1] == "ok" and seen[3] == 2_250_000_000
    assert one_by_one == [["power-on"], ["until"], ["until"], ["until"], [then]]
    if then == "state":
        assert ahead == [["power-on", "until", "until", "until", "state"]]
    else:
        # asked something else first: the `state` sent ahead is read and dropped
        assert ahead == [["power-on", "until", "until", "until", "state"], ["next"]]


def test_commands_sent_ahead_and_not_come_to_leave_the_clock_where_they_took_it():
    def act(line):
        line.power_on_ahead(2.25, state=True)
        line.write(b"!0SR6\r")          # the frame goes out after them, as sent
        answer = line.read(64, 0.5, b"\r")
        return answer, line.now

    ahead, (answer, now) = _writes(True, act)
    assert answer == b"0,00\r" and now > 2_250_000_000
    assert ahead == [["power-on", "until", "until", "until", "state"], ["tx"]]
