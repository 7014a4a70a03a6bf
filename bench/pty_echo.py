"""Bare pty servers for the benchmark's baselines: ``python -m bench.pty_echo`` prints
its pty's path, then writes back every byte it reads (an echo: the frame comes back as
it went); ``--answer`` writes ``0\\r`` for every CR instead (what the emulator answers to
``!0V1000``, with no work behind it). Ends on SIGTERM or when stdin closes."""

from __future__ import annotations

import os
import select
import sys
import tty


def main() -> None:
    answer = "--answer" in sys.argv[1:]
    master, slave = os.openpty()
    tty.setraw(slave)
    print(os.ttyname(slave), flush=True)
    poll = select.poll()
    poll.register(master, select.POLLIN)
    poll.register(sys.stdin.fileno(), select.POLLIN)
    while True:
        for fd, _ in poll.poll():
            if fd != master:
                return
            data = os.read(master, 1 << 16)
            os.write(master, b"0\r" * data.count(b"\r") if answer else data)


if __name__ == "__main__":
    main()
