"""The emulator's side of the co-simulation protocol (docs/cosim.md): in process, the
commands move the line's clock exactly as the in-process `gve://` line would (tx to the
end of the bytes, until stopping at a CR to the host), every byte reported once with
its instant; malformed commands are one `error:` line and change nothing; and
`python -m emulator --cosim` speaks it on standard input and output, with several
units on one line too."""

from __future__ import annotations

import io
import json
import re
import subprocess
import sys
from pathlib import Path

import pytest
import serial
from hypothesis import given, settings
from hypothesis import strategies as st

import emulator  # noqa: F401  (registers gve://)
from emulator.link.control import Quit
from emulator.link.cosim import Cosim, serve_cosim
from emulator.link.line import Line, byte_time
from emulator.link.url import LineSpec

BAUD = 115200
B = byte_time(BAUD)


#: the first line: the version and the extensions the emulator speaks
FIRST = "cosim 1 batch batch-stops pipeline"

def cosim(model: str = "GVE84-100") -> Cosim:
    spec = LineSpec(units=[(model, None)])
    return Cosim(Line(spec.build_units(), BAUD))


def rx(replies: list[str]) -> bytes:
    """The bytes of a reply's rx lines, checked to be one byte time apart in a line."""
    out = b""
    for reply in replies:
        word, t, data = reply.split()
        assert word == "rx" and int(t) > 0
        out += bytes.fromhex(data)
    return out


def test_tx_runs_the_clock_to_the_end_of_the_bytes_and_until_stops_at_the_cr():
    c = cosim()
    assert c.handle("tx 21303F0D") == [f"now {4 * B}"]         # the answer is on its way
    *got, now = c.handle("until 1000000000")
    reference = serial.serial_for_url("gve://?model=GVE84-100", timeout=1)
    reference.write(b"!0?\r")
    answer = reference.read_until(b"\r")
    assert rx(got) == answer and now == f"now {reference.line.now}"
    assert int(got[0].split()[1]) == 5 * B, "the first byte is complete one byte time on"
    assert c.handle("until 1000000000") == ["now 1000000000"]  # nothing more: on to T


def test_tx_with_an_instant_reads_the_answer_in_one_exchange():
    c = cosim()
    *got, now = c.handle("tx 21303F0D 1000000000")
    reference = serial.serial_for_url("gve://?model=GVE84-100", timeout=1)
    reference.write(b"!0?\r")
    assert rx(got) == reference.read_until(b"\r")
    assert now == f"now {reference.line.now}"


def test_answers_completed_during_the_bytes_end_tx_there_whatever_the_instant():
    c = cosim()
    frames = b"!0SR0\r!0SR1\r"
    *got, now = c.handle(f"tx {frames.hex()} 1000000000")
    assert rx(got) == b"0,00\r"                  # SR0's answer, complete during SR1
    assert now == f"now {len(frames) * B}"        # the clock stops at the bytes' end
    *rest, _ = c.handle("until 1000000000")
    assert rx(rest) == b"0,00\r"


def test_deferred_answers_and_events_on_the_way():
    """H answers when the axes have stopped: until stops at that answer's CR."""
    c = cosim()
    c.handle("tx " + b"!0V1000\r".hex() + " 100000000")
    c.handle("tx " + b"!0L5000,0,0\r".hex() + " 100000000")
    c.handle("until 500000000")
    c.handle("tx " + b"!0H\r".hex())
    *got, now = c.handle("until 9000000000")
    assert rx(got) == b"8\r"
    assert 500_000_000 < int(now.split()[1]) < 9_000_000_000
    assert c.handle("next") == ["next none"]


def test_next_names_what_is_due():
    c = cosim()
    c.handle("tx 21303F0D")
    assert c.handle("next") == [f"next {5 * B}"]


@pytest.mark.parametrize("text", ["tx", "tx 2", "tx ZZ", "tx 21 22 23", "until", "until -5",
                                  "until 1.5", "until 0 0", "next 1", "baud 0", "baud x",
                                  "fly", "tx 210D 1", "until \u00b2", "until " + "9" * 5000,
                                  "baud \u00b2", "baud " + "9" * 40, "tx 210D \u00b2",
                                  "batch \u00b2 210D", "in 1 \u00b2F", "switch X \u00b2"])
def test_malformed_commands_are_one_error_line_and_change_nothing(text):
    c = cosim()
    c.handle("until 1000")
    assert len(c.handle(text)) == 1 and c.handle(text)[0].startswith("error: ")
    assert c.line.now == 1000


def test_time_does_not_go_back():
    c = cosim()
    c.handle("until 5000")
    assert c.handle("until 4999")[0].startswith("error: until 4999: before now")


def test_baud_changes_the_byte_time():
    c = cosim()
    assert c.handle("baud 9600") == ["ok"]
    assert c.handle("tx 21303F0D") == [f"now {4 * byte_time(9600)}"]


def test_the_rig_s_commands_are_there_and_quit_ends():
    c = cosim()
    assert c.handle("in 1 FE") == ["ok"]
    assert json.loads(c.handle("state")[0])["inputs"]["1"] == "FE"
    assert c.handle("help")[0].startswith("commands: tx HEX [T] | until T")
    assert c.handle("") == []
    with pytest.raises(Quit):
        c.handle("quit")


def test_serve_cosim_announces_the_version_and_ends_at_the_end_of_input():
    out = io.StringIO()
    spec = LineSpec(units=[("GVE84-100", None)])
    serve_cosim(Line(spec.build_units(), BAUD), io.BytesIO(b"until 7\n\nnext\n"), out)
    assert out.getvalue() == f"{FIRST}\nnow 7\nnext none\n"


def test_a_line_that_is_too_long_is_refused():
    out = io.StringIO()
    spec = LineSpec(units=[("GVE84-100", None)])
    serve_cosim(Line(spec.build_units(), BAUD), io.BytesIO(b"x" * 70000 + b"\nuntil 3\n"), out)
    lines = out.getvalue().splitlines()
    assert lines[1].startswith("error: a command line longer than") and lines[2] == "now 3"


def test_python_m_emulator_cosim_with_several_units(tmp_path):
    log = tmp_path / "wire.gvt"
    commands = ("tx " + b"!1?\r".hex() + " 1000000000\nstate\nstate @1\nquit\n")
    done = subprocess.run([sys.executable, "-m", "emulator", "--unit", "GVE54@1", "--unit",
                           "GVE84-100@0", "--cosim", "--log", str(log)], input=commands,
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 0 and done.stderr == ""
    lines = done.stdout.splitlines()
    assert lines[0] == FIRST
    answer = rx([x for x in lines if x.startswith("rx ")])
    assert answer.startswith(b"0,") and answer.endswith(b"\r")
    both, one = (json.loads(x) for x in lines if x.startswith("{"))
    assert set(both) == {"0", "1"} and one["profile"] == "GVE54"
    assert "!1?" in log.read_text()


def test_python_m_emulator_cosim_ends_quietly_when_its_input_ends():
    done = subprocess.run([sys.executable, "-m", "emulator", "--cosim"], input="",
                          capture_output=True, text=True, timeout=60)
    assert (done.returncode, done.stdout, done.stderr) == (0, FIRST + "\n", "")


def test_the_session_in_docs_cosim_md_is_the_emulator_s():
    """The example session of docs/cosim.md, command by command, answered as written
    (the shortened `state` line by its beginning)."""
    doc = (Path(__file__).resolve().parents[3] / "docs" / "cosim.md").read_text()
    block = doc.split("## A session", 1)[1].split("```")[1]
    lines = [re.split(r"\s{3,}", x.strip())[0] for x in block.splitlines() if x.strip()]
    assert lines[0] == FIRST
    commands = [x[2:] for x in lines if x.startswith("> ")]
    expected = [x for x in lines[1:] if not x.startswith("> ")]
    done = subprocess.run([sys.executable, "-m", "emulator", "--model", "GVE84-100",
                           "--cosim"], input="\n".join(commands) + "\n",
                          capture_output=True, text=True, timeout=60)
    got = done.stdout.splitlines()
    assert got[0] == FIRST and len(got[1:]) == len(expected), got
    for want, have in zip(expected, got[1:], strict=True):
        if want.endswith(", ...}"):              # the keys shown, as shown
            shown = json.loads(want.replace(", ...}", "}"))
            assert {k: json.loads(have)[k] for k in shown} == shown
        else:
            assert have == want


def _now(replies: list[str]) -> int:
    word, t = replies[-1].split()
    assert word == "now"
    return int(t)


def test_batch_replies_as_its_frames_would_one_tx_each():
    """Each pair as `tx HEX T`, T its bytes' end + D."""
    frames = [(250_000_000, b"!0?\r"), (250_000_000, b"!0SR0\r"), (300_000_000, b"!0V1000\r"),
              (250_000_000, b"!0PF\r")]
    one, expected = cosim(), []
    for wait, data in frames:
        end = (_now(expected) if expected else 0) + len(data) * B
        expected += one.handle(f"tx {data.hex()} {end + wait}")
    got = cosim().handle("batch " + " ".join(f"{w} {d.hex().upper()}" for w, d in frames))
    assert got == expected
    assert sum(x.startswith("now ") for x in got) == 4 and _now(got) > 4 * B


def test_a_batch_ends_after_a_frame_that_got_no_cr():
    """`batch-stops`: an answer awaited too briefly (1 µs) ends the batch with that frame's
    `now`; the frames after it are not run (their answer comes in the next reply)."""
    frames = [(250_000_000, b"!0?\r"), (1_000, b"!0SR0\r"), (300_000_000, b"!0V1000\r")]
    one, expected = cosim(), []
    for wait, data in frames[:2]:
        end = (_now(expected) if expected else 0) + len(data) * B
        expected += one.handle(f"tx {data.hex()} {end + wait}")
    c = cosim()
    got = c.handle("batch " + " ".join(f"{w} {d.hex().upper()}" for w, d in frames))
    assert got == expected and sum(x.startswith("now ") for x in got) == 2
    later = c.handle(f"until {_now(got) + 300_000_000}")
    assert rx([x for x in later if x.startswith("rx ")]) == b"0,00\r", "SR0's answer, no V's"


@pytest.mark.parametrize("text", ["batch", "batch 5", "batch 5 ZZ", "batch x 2130",
                                  "batch 5 2130 7", "batch -1 2130"])
def test_a_malformed_batch_is_one_error_line_and_changes_nothing(text):
    c = cosim()
    reply = c.handle(text)
    assert len(reply) == 1 and reply[0].startswith("error: ")
    assert c.handle("until 1000") == ["now 1000"] and c.handle("next") == ["next none"]


words = st.sampled_from(["tx", "until", "next", "baud", "batch", "in", "switch", "state",
                         "power-on", "help", "210D", "1", "X", "none", "@0", "@9", "-5",
                         "\u00b2", "\u0663", "9" * 30, "", "0D" * 3, "1e5"])


@given(st.lists(st.one_of(words, st.text(max_size=6)), max_size=5).map(" ".join))
@settings(max_examples=300, deadline=None, derandomize=True)
def test_any_line_is_replies_never_a_crash(text):
    """Whatever a driver sends, the reply is lines (an error among them), and the clock
    never goes back: numbers are ASCII digits of bounded length, or an error."""
    c = cosim()
    before = c.line.now
    try:
        replies = c.handle(text)
    except Quit:
        return
    assert all(isinstance(r, str) and "\n" not in r for r in replies)
    assert c.line.now >= before


# -- the answers docs/cosim.md and docs/rig.md give a simulator's author ------------------------
def tx(c: Cosim, frame: bytes, until: int | None = None) -> list[str]:
    """`tx HEX [T]` of ``frame``."""
    return c.handle(f"tx {frame.hex().upper()}" + ("" if until is None else f" {until}"))


def test_an_empty_line_is_no_command_and_gets_no_reply():
    c = cosim()
    assert c.handle("") == [] and c.handle("  \r\n") == []
    assert c.line.now == 0


def test_help_is_one_line():
    (reply,) = cosim().handle("help")
    assert reply.startswith("commands: ")


def test_an_input_port_the_unit_lacks_is_taken_and_changes_nothing():
    """The GVE84 reads I1 only (its I2 is refused, 3) and has no interrupt behind port 2
    (ST1 enables nothing): `in 2 00` is a hand on a pin with nothing behind it."""
    c = cosim("GVE84-100")
    for frame in (b"!0SW1,FF\r", b"!0SW3,00\r"):
        tx(c, frame, 100000000)
    assert c.handle("in 2 00") == ["ok"]
    *got, _ = tx(c, b"!0SR6\r", 100000000)
    assert rx(got) == b"0,00\r"                          # no INTA: no interrupt
    *got, _ = tx(c, b"!0I2\r", 100000000)
    assert rx(got) == b"3\r"


def test_a_switch_is_seen_by_w_alone():
    """A rig's switch is a point W finds, releasing one step back: the input ports (I1)
    and the interrupts do not see it (the inputs enabled, their polarity as at reset)."""
    c = cosim("GVE84-100")
    tx(c, b"!0SW0,07\r", 100000000)
    assert c.handle("switch X -150") == ["ok"]
    for frame, answer in ((b"!0I1\r", b"0,FF\r"), (b"!0SR6\r", b"0,00\r")):
        *got, _ = tx(c, frame, 100000000)
        assert rx(got) == answer
    *got, _ = tx(c, b"!0WX,-1000,1000,100,500\r", 1000000000)
    assert rx(got) == b"0\r"                              # found, released, zeroed
    state = json.loads(c.handle("state")[0])
    assert state["position"][0] == 0 and state["physical"][0] == -149


def test_power_on_loses_what_arrives_while_it_restarts_and_keeps_what_is_on_the_line():
    """An answer already on its way to the host completes; bytes to the unit during the
    restart (the profile's restart_ms, 2 s) are lost; then it answers as after a reset."""
    c = cosim("GVE84-100")
    tx(c, b"!0?\r")                     # its answer has begun
    assert c.handle("power-on") == ["ok"]
    *got, _ = c.handle("until 100000000")
    assert rx(got).startswith(b"0,IP84")
    *got, _ = tx(c, b"!0?\r", 1900000000)
    assert rx(got) == b""                                 # deaf: lost
    c.handle("until 2100000000")
    *got, _ = tx(c, b"!0@\r", 2200000000)
    assert rx(got) == b"0,0\r"                            # the index of a fresh start


def test_an_answer_due_later_is_dropped_by_power_on():
    c = cosim("GVE84-100")
    tx(c, b"!0L5000,0,0\r", 100000000)
    c.handle("until 500000000")                           # at speed
    tx(c, b"!0H\r")                                       # answered once the axes stop
    assert c.handle("power-on") == ["ok"]
    assert c.handle("until 2000000000") == ["now 2000000000"]


def test_tx_with_an_instant_before_the_bytes_end_is_refused():
    c = cosim()
    (reply,) = tx(c, b"!0?\r", 3 * B)
    assert reply.startswith("error: ") and c.line.now == 0


def test_next_tells_the_watchdog_and_the_end_of_a_vector():
    c = cosim("GVE84-100")
    tx(c, b"!0")                                          # a frame left unfinished
    watchdog_ms = c.line.units[0].profile.watchdog_ms
    assert c.handle("next") == [f"next {2 * B + watchdog_ms * 1_000_000}"]
    *got, _ = c.handle("until 1000000000")
    assert rx(got) == b"2\r"                             # dropped, answered 2
    *_, now = tx(c, b"!0L100,0,0\r", c.line.now + 100000000)
    (due,) = c.handle("next")
    assert int(due.split()[1]) > int(now.split()[1])      # the vector's end, by itself
    c.handle(f"until {due.split()[1]}")
    *got, _ = tx(c, b"!0SR6\r", c.line.now + 100000000)
    assert rx(got) == b"0,00\r"                          # it had ended: idle


def test_an_event_at_the_instant_a_byte_completes_comes_first():
    """The watchdog drops an unfinished frame at its deadline (answering 2, the frame
    having its address); a CR completing at that very instant then ends no frame."""
    c = cosim("GVE84-100")
    tx(c, b"!0?")
    deadline = int(c.handle("next")[0].split()[1])
    c.handle(f"until {deadline - B}")
    *got, _ = tx(c, b"\r", deadline + 100000000)
    assert rx(got) == b"2\r"


def test_a_baud_change_keeps_the_byte_begun_and_times_the_rest_anew():
    c = cosim("GVE84-100")
    tx(c, b"!0?\r")                     # the answer's first byte begins
    assert c.handle("baud 9600") == ["ok"]
    *got, _ = c.handle("until 1000000000")
    instants = [int(r.split()[1]) for r in got if r.startswith("rx")]
    slow = byte_time(9600)
    assert instants[0] == 5 * B                           # begun at 115200 baud
    runs = [(int(t), len(bytes.fromhex(d))) for _, t, d in (r.split() for r in got)]
    ends = [t + (n - 1) * slow for t, n in runs]
    assert ends[-1] == 5 * B + 19 * slow                   # 19 bytes more at 9600 baud


def _ask(p: subprocess.Popen, command: str) -> list[str]:
    """One command to a running `--cosim`, its reply lines up to the final one."""
    p.stdin.write(command + "\n")
    p.stdin.flush()
    lines = []
    while True:
        lines.append(p.stdout.readline().strip())
        if not lines[-1].startswith("rx "):
            return lines


def test_snapshot_and_restore_are_offered_only_when_asked():
    done = subprocess.run([sys.executable, "-m", "emulator", "--cosim"],
                          input="snapshot\nrestore\n", capture_output=True, text=True,
                          timeout=60)
    first, *replies = done.stdout.splitlines()
    assert "snapshot" not in first.split()
    assert [r.split(":")[0] for r in replies] == ["error", "error"]


def test_restore_brings_back_the_state_kept_and_the_clock_does_not_go_back():
    p = subprocess.Popen([sys.executable, "-m", "emulator", "--model", "GVE84-100", "--cosim",
                          "--snapshot"], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                         text=True)
    try:
        assert p.stdout.readline().split()[2:] == ["batch", "batch-stops", "pipeline", "snapshot"]
        assert _ask(p, "restore")[0].startswith("error: restore: no snapshot")
        assert _ask(p, "snapshot") == ["ok"]
        moved = _now(_ask(p, "tx " + b"!0L100,0,0\r".hex() + " 300000000"))
        _ask(p, f"until {moved + 300_000_000}")
        where = _ask(p, "tx " + b"!0PF\r".hex() + f" {moved + 400_000_000}")
        assert rx(where[:-1]) == b"0,100,0,0\r"
        for _ in range(3):          # each restore from the same kept state
            before = _now(_ask(p, f"until {moved + 500_000_000}"))
            assert _ask(p, "restore") == [f"now {before}"]
            back = _ask(p, "tx " + b"!0PF\r".hex() + f" {before + 100_000_000}")
            assert rx(back[:-1]) == b"0,0,0,0\r" and _now(back) > before
            moved = _now(back)
        _ask(p, "quit")
        assert p.wait(30) == 0              # the process started ends, the keeper's last
    finally:
        if p.poll() is None:
            p.kill()
        p.stdin.close()
        p.stdout.close()
