"""The program behind an exec: target: lines out and in, why it ended, and stopping it —
asked with `quit`, else terminated, else killed, and what it started ended too: no
zombie, no orphan."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading

import pytest

from conformance.targets import program as program_module
from conformance.targets.program import Program, ProgramError

#: reads standard input and answers every line; ends on `quit`
ECHO = [sys.executable, "-c",
        "import sys\nprint('ready', flush=True)\nfor line in sys.stdin:\n"
        "    if line.strip() == 'quit': break\n    print('got ' + line.strip(), flush=True)"]
#: ignores `quit` and SIGTERM: only SIGKILL ends it
STUBBORN = [sys.executable, "-c",
            "import signal, sys, time\nsignal.signal(signal.SIGTERM, signal.SIG_IGN)\n"
            "print('ready', flush=True)\nsys.stdin.read()\ntime.sleep(60)"]


def running(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as stat:
            return stat.read().rsplit(")", 1)[1].split()[0] not in "ZX"
    except FileNotFoundError:
        return False


@pytest.fixture
def quick(monkeypatch):
    monkeypatch.setattr(program_module, "QUIT_SECONDS", 0.3)
    monkeypatch.setattr(program_module, "TERM_SECONDS", 0.3)


def test_lines_out_and_in_and_quit_ends_it():
    p = Program(ECHO)
    assert p.line(10) == "ready"
    assert p.send("hello")
    assert p.line(10) == "got hello"
    p.stop()
    assert p.process.returncode == 0, "quit should have ended it"
    assert not running(p.process.pid)
    p.stop()                                  # idempotent


def test_lines_come_in_order_and_none_is_made_up():
    p = Program(ECHO)
    try:
        assert p.line(10) == "ready"
        for word in ("one", "two", "three"):
            p.send(word)
        assert [p.line(10) for _ in range(3)] == ["got one", "got two", "got three"]
        assert p.discard() == []
        assert p.line(0.05) is None           # nothing more was printed
    finally:
        p.stop()


#: answers `go` at once, then again once its second line, on the next `go`, has waited
#: well past the poll a reader makes before it sleeps
LATER = [sys.executable, "-c",
         "import sys, time\nprint('ready', flush=True)\nsys.stdin.readline()\n"
         "print('at once', flush=True)\nsys.stdin.readline()\ntime.sleep(0.2)\n"
         "print('later', flush=True)\nsys.stdin.read()"]


def test_a_line_awaited_is_read_whether_it_comes_while_the_reader_polls_or_after():
    p = Program(LATER)
    try:
        assert p.line(10) == "ready"
        assert p.line(program_module.POLL_SECONDS / 2) is None   # a timeout within the poll
        p.send("go")
        assert p.line(10) == "at once"
        p.send("go")
        assert p.line(10) == "later"              # came after the poll: the reader slept
        assert p.line(0.05) is None
    finally:
        p.stop()


def test_a_stopped_program_s_reader_has_ended_and_the_next_program_s_line_comes_whole():
    first = Program(ECHO)
    assert first.line(10) == "ready"
    first.read_in_background()
    first.stop()
    assert f"exec-{first.process.pid}" not in {t.name for t in threading.enumerate()}
    # the next program's descriptors may take the numbers the first one's had: nothing
    # of the first one reads them, so a line written in two pieces comes whole
    pieces = [sys.executable, "-c", "import os\nos.write(1, b'/dev/pts/')\nos.write(1, b'7\\n')"]
    second = Program(pieces)
    try:
        assert second.line(10) == "/dev/pts/7"
    finally:
        second.stop()


def test_a_program_deaf_to_quit_and_sigterm_is_killed(quick):
    p = Program(STUBBORN)
    assert p.line(10) == "ready"
    p.stop()
    assert p.process.returncode == -signal.SIGKILL
    assert not running(p.process.pid)


def test_what_the_program_started_is_ended_with_it(quick):
    # the child runs on after its parent (cat) ends: an orphan unless its group is ended
    p = Program(["sh", "-c", "sleep 60 & echo $!; exec cat"])
    child = int(p.line(10) or 0)
    assert running(child)
    p.stop()
    assert not running(child)


def test_how_it_ended_names_the_command_the_status_and_stderr():
    p = Program(["sh", "-c", "echo first >&2; echo last words >&2; exit 3"])
    assert p.line(10) is None                 # its output ended
    assert p.wait(10)
    assert p.ended() == "sh -c 'echo first >&2; echo last words >&2; exit 3' exited with " \
                        'status 3 (stderr: "last words")'
    p.stop()


def test_a_program_killed_by_a_signal_says_so():
    p = Program(ECHO)
    assert p.ended() == ""
    os.kill(p.process.pid, signal.SIGKILL)
    assert p.wait(10)
    assert "was killed by signal 9" in p.ended()
    assert not p.send("anything")             # nobody reads it any more: no exception
    p.stop()


def test_a_program_that_cannot_start_is_one_line():
    with pytest.raises(ProgramError, match="cannot start 'no-such-program-here': No such "
                                           "file or directory"):
        Program(["no-such-program-here"])


def test_a_program_left_running_is_stopped_when_the_interpreter_exits():
    script = ("import sys\nfrom conformance.targets.program import Program\n"
              f"p = Program({ECHO!r})\nprint(p.process.pid, flush=True)\nsys.exit(2)")
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                          timeout=60, check=False)
    assert done.returncode == 2 and done.stderr == "", done.stderr
    assert not running(int(done.stdout))
