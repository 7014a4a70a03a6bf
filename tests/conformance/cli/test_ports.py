"""`gve-conformance ports --probe` disturbs nobody: a port another program holds
(TIOCEXCL, a lock) gets no byte and keeps its settings, and says
why it was skipped; a free port gets `?` only and its settings back; a pseudo-terminal
that was not named (found by a glob, as the docs' `--glob '/dev/pts/*'`: somebody's
interactive terminal) gets no byte at all. The listing's last line counts what it found
and what each probe said."""

from __future__ import annotations

import fcntl
import os
import termios

import pytest

from conformance.cli import main, ports
from tests.conformance.link.test_exclusive import pending, pty  # noqa: F401  (fixture)


@pytest.fixture(autouse=True)
def only_globbed(monkeypatch):
    """The machine's own ports left out: the probe sees the test's pty alone."""
    monkeypatch.setattr(ports.list_ports, "comports", lambda include_links: [])


def probe(path: str, capsys) -> str:
    assert main(["ports", "--probe", path]) == 0         # named: a pty too is asked
    out = capsys.readouterr().out.splitlines()
    assert len(out) == 2 and out[0].startswith(path)
    assert out[1].startswith("1 port listed; ")
    return out[0]


def cooked(fd: int) -> list:
    """Settings no probe would leave: canonical, echoing, 9600 baud, 7E1."""
    attrs = termios.tcgetattr(fd)
    attrs[2] = (attrs[2] & ~termios.CSIZE) | termios.CS7 | termios.PARENB
    attrs[3] |= termios.ICANON | termios.ECHO
    attrs[4] = attrs[5] = termios.B9600
    termios.tcsetattr(fd, termios.TCSANOW, attrs)
    return termios.tcgetattr(fd)


def test_a_port_held_with_tiocexcl_is_skipped_untouched(pty, capsys):  # noqa: F811
    master, slave, path = pty
    settings = cooked(slave)
    fcntl.ioctl(slave, termios.TIOCEXCL)
    line = probe(path, capsys)
    assert line.endswith("-> skipped: another program holds it exclusively (TIOCEXCL)")
    assert pending(master) == b""
    assert termios.tcgetattr(slave) == settings


def test_a_port_another_run_has_locked_is_skipped_untouched(pty, capsys):  # noqa: F811
    master, slave, path = pty
    settings = cooked(slave)
    fcntl.flock(slave, fcntl.LOCK_EX | fcntl.LOCK_NB)
    assert "-> skipped: another program holds it locked" in probe(path, capsys)
    assert pending(master) == b""
    assert termios.tcgetattr(slave) == settings


def test_a_free_port_is_asked_only_and_gets_its_settings_back(pty, capsys):  # noqa: F811
    master, slave, path = pty
    settings = cooked(slave)
    assert probe(path, capsys).endswith("-> no GVE unit answered")
    assert termios.tcgetattr(slave) == settings
    sent = pending(master)
    assert sent and set(sent.split(b"\r")) == {b"!0?", b""}       # `?` at each rate


def test_what_is_no_serial_device_is_skipped(tmp_path, capsys):
    plain = tmp_path / "ttyUSB-file"
    plain.write_text("")
    assert probe(str(plain), capsys).endswith("-> skipped: not a serial device")
    assert plain.read_text() == ""


def test_a_pseudo_terminal_a_glob_found_gets_no_byte(pty, capsys):  # noqa: F811
    master, slave, path = pty
    settings = cooked(slave)
    assert main(["ports", "--glob", path, "--probe"]) == 0
    line, last = capsys.readouterr().out.splitlines()
    assert last == ("1 port listed; a GVE unit answered on 0, no answer on 0, 1 skipped "
                    "untouched")
    assert line.endswith(f"-> skipped: a pseudo-terminal (an interactive terminal, or "
                         f"another program's line): probed only when named, "
                         f"gve-conformance ports --probe {path}")
    assert pending(master) == b""
    assert termios.tcgetattr(slave) == settings
    assert ports.is_pseudo_terminal(path) and not ports.is_pseudo_terminal("/dev/null")


@pytest.mark.parametrize(("name", "major", "pseudo"), [
    ("/dev/ttyS0", 4, False),          # a serial port, whose name the old pty names resemble
    ("/dev/ttyUSB0", 188, False),
    ("/dev/pts/7", 136, True),
    ("/dev/ttyp0", 3, True),
])
def test_a_device_is_classified_by_its_major_not_its_name(monkeypatch, name, major, pseudo):
    real_stat = os.stat

    def stat(path, *args, **kw):
        return _device(major) if path == name else real_stat(path, *args, **kw)
    monkeypatch.setattr(ports.sys, "platform", "linux")
    monkeypatch.setattr(ports.os.path, "realpath", lambda p: p)
    monkeypatch.setattr(ports.os, "stat", stat)
    assert ports.is_pseudo_terminal(name) == pseudo


def _device(major: int):
    """What os.stat says of a character device with ``major``."""
    class Device:
        st_rdev = os.makedev(major, 64)
    return Device()

