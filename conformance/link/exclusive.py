"""A serial port this machine's run holds alone: a path (``/dev/ttyUSB0``, a pty) is
opened only when no other program holds it, then locked two ways for as long as the run
has it open — pyserial's ``exclusive=True`` (``flock``: another run is refused) and
``TIOCEXCL`` (the kernel refuses every other open but root's). A port that is held
already is refused before anything changes on it: its settings untouched, nothing sent.

``TIOCEXCL`` outlives the last close of a pty whose master is still open, so it is
cleared before the port is closed. Root opens a ``TIOCEXCL`` port regardless; the flag
is therefore also read (``TIOCGEXCL``) and honoured.

:func:`settings_kept` is for a look at a port that is not the run's (``ports
--probe``): a port held is skipped, the settings of any other put back as found."""

from __future__ import annotations

import errno
import fcntl
import os
import stat
import struct
import sys
import termios
from collections.abc import Iterator
from contextlib import contextmanager, suppress

import serial

HELD_EXCLUSIVELY = "another program holds it exclusively (TIOCEXCL)"

#: Linux's _IOR('T', 0x40, int), which Python's termios does not name (elsewhere: unasked)
TIOCGEXCL = getattr(termios, "TIOCGEXCL",
                    0x80045440 if sys.platform.startswith("linux") else None)


class LeftAlone(serial.SerialException):
    """A port left as it was found (one line saying why, after the port's name)."""


class PortHeld(LeftAlone):
    """Another program holds the port."""


def look(path: str) -> int:
    """A descriptor on ``path`` that changes nothing on it (no settings, no lock kept),
    after making sure no other program holds it: PortHeld when one does, OSError when
    ``path`` cannot be opened at all."""
    try:
        fd = os.open(path, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
    except OSError as err:
        if err.errno == errno.EBUSY:
            raise PortHeld(HELD_EXCLUSIVELY) from None
        raise
    try:
        _refuse_if_held(fd)
    except BaseException:
        os.close(fd)
        raise
    return fd


def _refuse_if_held(fd: int) -> None:
    if os.isatty(fd) and _exclusive(fd):
        raise PortHeld(HELD_EXCLUSIVELY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError as err:
        if err.errno in (errno.EWOULDBLOCK, errno.EAGAIN):
            raise PortHeld("another program holds it locked (flock: another run on "
                           "it?)") from None
        return
    fcntl.flock(fd, fcntl.LOCK_UN)        # pyserial takes the lock on its own descriptor


def _exclusive(fd: int) -> bool:
    if TIOCGEXCL is None:
        return False                      # the kernel's EBUSY tells (but root's)
    try:
        flag = fcntl.ioctl(fd, TIOCGEXCL, struct.pack("i", 0))
    except OSError:
        return False
    return struct.unpack("i", flag)[0] != 0


class HeldSerial(serial.Serial):
    """pyserial's port on a path of this machine, held alone while it is open."""

    def __init__(self, *args, **kwargs) -> None:
        super().__init__(*args, exclusive=True, **kwargs)

    def open(self) -> None:
        try:
            guard = look(self.portstr) if self.portstr is not None else None
        except PortHeld:
            raise
        except OSError:
            guard = None                  # pyserial says why, as it always does
        try:                              # the guard held open: no hang-up in between
            super().open()
        finally:
            if guard is not None:
                os.close(guard)
        try:
            fcntl.ioctl(self.fd, termios.TIOCEXCL)
        except OSError as err:
            self.close()
            raise serial.SerialException(f"cannot hold {self.portstr} exclusively: "
                                         f"{err.strerror}") from None

    def close(self) -> None:
        if self.is_open and self.fd is not None:
            with suppress(OSError):
                fcntl.ioctl(self.fd, termios.TIOCNXCL)
        super().close()


def open_serial(url: str, **kwargs) -> serial.SerialBase:
    """The port at ``url``: a path held alone (:class:`HeldSerial`), any other pyserial
    URL (``socket://``, ``rfc2217://``, ``loop://``, ``gve://``) as pyserial opens it."""
    if "://" in url:
        return serial.serial_for_url(url, **kwargs)
    return HeldSerial(url, **kwargs)


@contextmanager
def settings_kept(path: str) -> Iterator[None]:
    """What is done inside on ``path`` (opening it anew), its terminal settings put back
    afterwards as they were found. LeftAlone before anything changes when it is no
    terminal, or PortHeld when another program holds it."""
    try:
        device = stat.S_ISCHR(os.stat(path).st_mode)
        guard = look(path) if device else None
    except PortHeld:
        raise
    except OSError as err:
        raise LeftAlone(f"cannot open it: {err.strerror or err}") from None
    if guard is None:
        raise LeftAlone("not a serial device")
    try:
        try:
            saved = termios.tcgetattr(guard)
        except termios.error:
            raise LeftAlone("not a terminal") from None
        try:
            yield
        finally:
            termios.tcsetattr(guard, termios.TCSANOW, saved)
    finally:
        os.close(guard)
