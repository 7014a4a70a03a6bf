"""A port is the run's alone: a path is opened only when no other program holds it
(TIOCEXCL or another run's lock), refused then before its settings change or a byte is
sent — one line and exit 2 through every command — and free again once it is closed."""

from __future__ import annotations

import fcntl
import os
import select
import subprocess
import sys
import termios

import pytest

from conformance.link.exclusive import TIOCGEXCL, PortHeld, open_serial

#: the commands that open a unit's (or a host's) port, the port's path put in for {}
COMMANDS = {
    "suite": ["--target", "serial:{}", "--profile", "GVE54", "--yes", "--no-reports"],
    "diff": ["diff", "--target", "serial:{}", "--profile", "GVE54", "--yes",
             "--no-reports", "--examples", "3"],
    "host": ["host", "--port", "{}", "--profile", "GVE54", "--no-reports", "--",
             sys.executable, "-c", "pass", "{port}"],
}


@pytest.fixture
def pty():
    """(master, slave, path) of a new pseudo-terminal; what reaches the port is read on
    the master."""
    master, slave = os.openpty()
    yield master, slave, os.ttyname(slave)
    os.close(master)
    os.close(slave)


def pending(master: int) -> bytes:
    """Whatever was written to the port and not read yet (never waits)."""
    data = b""
    while select.select([master], [], [], 0)[0]:
        data += os.read(master, 4096)
    return data


def exclusive(fd: int) -> bool:
    return fcntl.ioctl(fd, TIOCGEXCL, b"\0" * 4) != b"\0" * 4


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_a_second_open_of_a_port_exits_2_with_one_line(pty, command):
    master, slave, path = pty
    first = open_serial(path, baudrate=115200, timeout=0.5)      # a run holding it
    try:
        settings = termios.tcgetattr(slave)
        argv = [a.replace("{}", path) for a in COMMANDS[command]]
        proc = subprocess.run([sys.executable, "-m", "conformance", *argv],
                              capture_output=True, text=True, timeout=60)
        assert proc.returncode == 2
        assert proc.stderr.count("\n") == 1
        assert "another program holds it exclusively" in proc.stderr
        assert pending(master) == b"" and termios.tcgetattr(slave) == settings
    finally:
        first.close()


def test_another_runs_lock_alone_refuses_the_port(pty):
    master, slave, path = pty
    other = os.open(path, os.O_RDWR | os.O_NOCTTY)
    fcntl.flock(other, fcntl.LOCK_EX | fcntl.LOCK_NB)    # a run of an older suite, say
    try:
        settings = termios.tcgetattr(slave)
        with pytest.raises(PortHeld, match=r"locked \(flock"):
            open_serial(path, baudrate=115200)
        assert termios.tcgetattr(slave) == settings and pending(master) == b""
    finally:
        os.close(other)


def test_a_port_is_held_while_open_and_free_once_closed(pty):
    master, slave, path = pty
    port = open_serial(path, baudrate=115200, timeout=0.5)
    assert exclusive(slave)
    with pytest.raises(PortHeld):
        open_serial(path, baudrate=115200)
    port.write(b"!0?\r")
    port.close()
    assert not exclusive(slave)      # on a pty the flag would outlive the close
    again = open_serial(path, baudrate=115200)
    again.close()
    assert pending(master) == b"!0?\r"


def test_urls_are_opened_as_pyserial_opens_them():
    port = open_serial("loop://", timeout=0)
    port.write(b"?")
    assert port.read(1) == b"?"
    port.close()
