"""The target's port as the links see it: pyserial's port, except that when it fails
(a USB adapter unplugged, a TCP peer gone, a simulator's program ended) the target is
gone — :class:`TargetNotResponding` saying why, never an error of the suite, never a
wait for frames nobody answers."""

from __future__ import annotations

import termios
from contextlib import suppress
from typing import NoReturn, Protocol

import serial

from conformance.link.liveness import TargetNotResponding

#: after the port failed, how long a program may take to be seen ending
ENDING_SECONDS = 1.0

#: how a port's failure shows: a pseudo-terminal whose program ended is hung up, and on
#: it every ioctl fails — pyserial's reads and writes say so as SerialException/OSError,
#: its tcflush, tcdrain and tcsetattr as termios.error (no OSError)
_FAILURES = (serial.SerialException, OSError, termios.error)


class Program(Protocol):
    """What the port needs to know of a program behind it (targets/program.py)."""

    @property
    def alive(self) -> bool: ...

    def wait(self, seconds: float) -> bool: ...

    def ended(self) -> str: ...


class TargetPort:
    """``port`` whose failures end the target; ``program``, when a program serves the
    port, is asked whether it ended (then a silent read is the end too)."""

    def __init__(self, port: serial.SerialBase, program: Program | None = None) -> None:
        self._port = port
        self._program = program

    def _gone(self, err: Exception | None = None) -> NoReturn:
        program = self._program
        if program is not None and program.alive:
            program.wait(ENDING_SECONDS)
        ended = program.ended() if program is not None else ""
        raise TargetNotResponding(f"the target's program ended: {ended}" if ended else
                                  f"the target's port failed: {err}")

    def _ended(self) -> bool:
        return self._program is not None and not self._program.alive

    def read(self, size: int = 1) -> bytes:
        try:
            data = self._port.read(size)
        except _FAILURES as err:
            self._gone(err)
        if not data and self._ended():
            self._gone()
        return data

    def read_until(self, expected: bytes = b"\n", size: int | None = None) -> bytes:
        try:
            data = self._port.read_until(expected, size)
        except _FAILURES as err:
            self._gone(err)
        if not data.endswith(expected) and self._ended():
            self._gone()
        return data

    def write(self, data: bytes) -> int | None:
        if self._ended():
            self._gone()
        try:
            return self._port.write(data)
        except _FAILURES as err:
            self._gone(err)

    @property
    def in_waiting(self) -> int:
        try:
            return self._port.in_waiting
        except _FAILURES as err:
            self._gone(err)

    @property
    def timeout(self) -> float | None:
        return self._port.timeout

    @timeout.setter
    def timeout(self, value: float | None) -> None:
        try:
            self._port.timeout = value             # pyserial reconfigures the port
        except _FAILURES as err:
            self._gone(err)

    def reset_input_buffer(self) -> None:
        try:
            self._port.reset_input_buffer()
        except _FAILURES as err:
            self._gone(err)

    def flush(self) -> None:
        try:
            self._port.flush()
        except _FAILURES as err:
            self._gone(err)

    def close(self) -> None:
        with suppress(*_FAILURES):                # already gone: nothing left to release
            self._port.close()

    def __getattr__(self, name: str):
        return getattr(self._port, name)          # the rest as pyserial has it
