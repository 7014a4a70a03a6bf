"""A clone's simulator that dies at an instant of its own protocol:

    python dying_relay.py BODY WHEN [EMULATOR OPTIONS...]

It starts the emulator (``python -m emulator --pty OPTIONS``), serves a pseudo-terminal
of its own (its path the first line it prints, docs/rig.md) and relays the bytes both
ways, until the first host frame whose body is BODY (``!0Z`` or ``!0Z,5A``: ``Z``). Then
it kills itself with SIGKILL (its pty hung up at once), WHEN:

- ``before``: the frame read whole, nothing of it passed on, so never answered;
- ``mid-answer``: the frame passed on, the first byte of its answer relayed and read;
- ``after``: the frame passed on, its whole answer relayed (up to its CR) and read.

"Read": it waits until the suite has taken those bytes off its pty (it holds the pty's
other side too, whose input queue it asks), so that the suite has seen them.

Its standard input is closed at once: the suite finds no rig, without waiting for one.
"""

from __future__ import annotations

import fcntl
import os
import select
import signal
import struct
import subprocess
import sys
import termios
import time
import tty

CR = b"\r"


def die() -> None:
    os.kill(os.getpid(), signal.SIGKILL)


def taken(ours: int) -> None:
    """Return once the suite has read every byte relayed to it."""
    while struct.unpack("i", fcntl.ioctl(ours, termios.FIONREAD, b"\0" * 4))[0]:
        time.sleep(0.001)


def body_of(frame: bytes) -> bytes:
    """``!0XQ,26`` → ``XQ``: the frame's body without address nor checksum."""
    return frame[2:].split(b",")[0]


def main(argv: list[str]) -> None:
    body, when, options = argv[0].encode(), argv[1], argv[2:]
    os.close(0)
    emulator = subprocess.Popen([sys.executable, "-m", "emulator", "--pty", *options],
                                stdin=subprocess.DEVNULL, stdout=subprocess.PIPE)
    unit = os.open(emulator.stdout.readline().decode().strip(), os.O_RDWR | os.O_NOCTTY)
    tty.setraw(unit)
    host, ours = os.openpty()
    tty.setraw(ours)
    print(os.ttyname(ours), flush=True)
    pending = b""                 # host bytes not yet a whole frame
    dying = False                 # the fatal frame passed on: die in its answer
    while True:
        ready = select.select([host, unit], [], [])[0]
        if host in ready:
            data = os.read(host, 4096)
            pending += data
            while CR in pending:
                frame, _, pending = pending.partition(CR)
                if body_of(frame) == body and not dying:
                    if when == "before":
                        die()
                    dying = True
                os.write(unit, frame + CR)
        if unit in ready:
            data = os.read(unit, 1 if dying else 4096)
            os.write(host, data)
            if dying and (when == "mid-answer" or data == CR):
                taken(ours)
                die()


if __name__ == "__main__":
    main(sys.argv[1:])
