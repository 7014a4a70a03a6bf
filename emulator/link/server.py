"""Serving a line in real time on a pseudo-terminal or a TCP port.

One loop waits (poll) for bytes from the host, control lines on standard input, a
signal, or the next instant something is due on the line (an answer's bytes, an H
answer, the watchdog, a restart), and hands every byte that is due to the host.

Nothing a host or a controller does can stop that loop: answers go out as the host
takes them, and a host that stops reading loses the answers beyond
:data:`OUTPUT_LIMIT` (never the unit's time or the control channel); control input is
read as it comes, a partial line waits without blocking anything, and each complete
line gets its reply; the unit itself never holds more than a frame's worth of an
unfinished frame (the framer). SIGINT/SIGTERM, `quit`, and a closed standard output
(the reader is gone) end it cleanly.
"""

from __future__ import annotations

import contextlib
import os
import select
import signal
import socket
import sys
import termios
import tty
from collections.abc import Callable

from emulator.link.control import Quit, handle
from emulator.link.line import Line
from gve_fixtures.protocol import SECOND

#: answers held for a host that does not read; beyond this they are lost
OUTPUT_LIMIT = 1 << 16
#: a control line longer than this without its newline is refused
CONTROL_LIMIT = 1 << 16
READ_SIZE = 1 << 16
#: reads of a connected host's bytes before a newcomer is turned away
CHECK_READS = 16
_ERRORS = select.POLLERR | select.POLLHUP | select.POLLNVAL


class StdoutGone(Exception):
    """Standard output was closed by its reader: the program ends quietly."""


def say(text: str) -> None:
    """One line on standard output (the port, control replies), in one write: a reader
    never sees half of it, also when Python's output is unbuffered."""
    try:
        sys.stdout.write(text + "\n")
        sys.stdout.flush()
    except BrokenPipeError:
        raise StdoutGone from None


def silence_stdout() -> None:
    """After the reader of standard output went away: nothing more goes there (not even
    the interpreter's last flush)."""
    with contextlib.suppress(OSError, ValueError):
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)


class Outbox:
    """Bytes for a host on a non-blocking descriptor: sent as it takes them, held up to
    OUTPUT_LIMIT; answers that do not fit are dropped whole."""

    def __init__(self) -> None:
        self.pending = bytearray()
        self.dropped = 0

    def put(self, data: bytes, send: Callable[[bytes], int]) -> None:
        if not self.pending:                  # the usual case: the host takes it at once
            try:
                n = send(data)
            except (BlockingIOError, InterruptedError):
                n = 0
            except OSError:
                return                        # the host is gone: nobody to read it
            data = data[n:]
            if not data:
                return
        if len(self.pending) + len(data) > OUTPUT_LIMIT:
            self.dropped += len(data)
            return
        self.pending += data
        self.flush(send)

    def flush(self, send: Callable[[bytes], int]) -> None:
        while self.pending:
            try:
                n = send(bytes(self.pending))
            except (BlockingIOError, InterruptedError):
                return
            except OSError:
                self.pending.clear()           # the host is gone: nobody to read it
                return
            if n <= 0:
                return
            del self.pending[:n]


class Host:
    """Where the host's bytes come from and go to (a pty or a TCP connection)."""

    def register(self, poll: select.poll) -> None: ...
    def on_event(self, fd: int, events: int, line: Line, poll: select.poll) -> None: ...
    def send(self, data: bytes, poll: select.poll) -> None: ...
    def close(self) -> None: ...


class PtyHost(Host):
    def __init__(self) -> None:
        self.master, self.slave = os.openpty()
        tty.setraw(self.slave)
        attrs = termios.tcgetattr(self.slave)
        attrs[3] &= ~termios.ECHO
        termios.tcsetattr(self.slave, termios.TCSANOW, attrs)
        os.set_blocking(self.master, False)
        self.name = os.ttyname(self.slave)
        self.out = Outbox()

    def _write(self, data: bytes) -> int:
        return os.write(self.master, data)

    def _events(self) -> int:
        return select.POLLIN | (select.POLLOUT if self.out.pending else 0)

    def register(self, poll: select.poll) -> None:
        poll.register(self.master, self._events())

    def on_event(self, fd: int, events: int, line: Line, poll: select.poll) -> None:
        if events & select.POLLIN:
            try:
                data = os.read(self.master, READ_SIZE)
            except OSError:                   # EAGAIN, EINTR, EIO: nothing to take
                data = b""
            if data:
                line.write(data)
        if events & select.POLLOUT:
            self.out.flush(self._write)
            poll.modify(self.master, self._events())

    def send(self, data: bytes, poll: select.poll) -> None:
        self.out.put(data, self._write)
        if self.out.pending:
            poll.modify(self.master, self._events())

    def close(self) -> None:
        os.close(self.master)
        os.close(self.slave)


class TcpHost(Host):
    """One host at a time on a TCP port; others are turned away while it is connected.
    Whether it still is, is asked before a newcomer is turned away: a host that closed
    and at once connected again is served, though poll told of the new connection
    before the old one's end."""

    def __init__(self, host: str, port: int) -> None:
        self.listener = socket.create_server((host, port), reuse_port=False)
        self.listener.setblocking(False)
        self.name = f"tcp {host}:{self.listener.getsockname()[1]}"
        self.conn: socket.socket | None = None
        self.out = Outbox()

    def _events(self) -> int:
        return select.POLLIN | (select.POLLOUT if self.out.pending else 0)

    def register(self, poll: select.poll) -> None:
        poll.register(self.listener, select.POLLIN)

    def _drop(self, poll: select.poll) -> None:
        if self.conn is not None:
            poll.unregister(self.conn)
            self.conn.close()
            self.conn = None
            self.out = Outbox()

    def on_event(self, fd: int, events: int, line: Line, poll: select.poll) -> None:
        if fd == self.listener.fileno():
            with contextlib.suppress(BlockingIOError, InterruptedError):
                conn, _ = self.listener.accept()
                if self._connected(line, poll):
                    conn.close()
                    return
                conn.setblocking(False)
                conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
                self.conn = conn
                poll.register(conn, self._events())
            return
        conn = self.conn
        if conn is None or fd != conn.fileno():
            return
        if events & (select.POLLIN | _ERRORS):
            try:
                data = conn.recv(READ_SIZE)
            except (BlockingIOError, InterruptedError):
                data = None
            except OSError:
                data = b""
            if data == b"":
                self._drop(poll)
                return
            if data:
                line.write(data)
        if events & select.POLLOUT:
            self.out.flush(conn.send)
            poll.modify(conn, self._events())

    def _connected(self, line: Line, poll: select.poll) -> bool:
        """Whether a host is still connected, the bytes it sent taken first (up to
        :data:`CHECK_READS` reads: one that keeps sending is there)."""
        for _ in range(CHECK_READS):
            if self.conn is None:
                return False
            try:
                data = self.conn.recv(READ_SIZE)
            except (BlockingIOError, InterruptedError):
                return True
            except OSError:
                data = b""
            if data == b"":
                self._drop(poll)
                return False
            line.write(data)
        return True

    def send(self, data: bytes, poll: select.poll) -> None:
        if self.conn is None:
            return
        self.out.put(data, self.conn.send)
        if self.out.pending:
            poll.modify(self.conn, self._events())

    def close(self) -> None:
        if self.conn is not None:
            self.conn.close()
        self.listener.close()


class ControlReader:
    """Control lines from a descriptor, read as they come (docs/rig.md)."""

    def __init__(self, fd: int) -> None:
        self.fd = fd                          # left blocking: it may be the terminal's
        self.partial = bytearray()

    def read(self, line: Line) -> bool:
        """Run the complete lines that arrived (poll said some did); False at end of
        input."""
        try:
            data = os.read(self.fd, READ_SIZE)
        except InterruptedError:
            return True
        except OSError:
            return False
        if not data:
            return False
        self.partial += data
        *lines, rest = self.partial.split(b"\n")
        self.partial = bytearray(rest)
        if len(self.partial) > CONTROL_LIMIT:
            self.partial.clear()
            say(f"error: a control line longer than {CONTROL_LIMIT} bytes")
        for raw in lines:
            answer = handle(line, raw.decode("utf-8", "replace"))
            if answer is not None:
                say(answer)
        return True


def serve(line: Line, host: Host, control: int | None) -> None:
    """Serve ``line`` to ``host`` until a signal, `quit`, or standard output's reader
    goes away. ``control`` is the control channel's descriptor (None: none)."""
    stop: list[bool] = []
    wake_r, wake_w = os.pipe()
    os.set_blocking(wake_r, False)
    os.set_blocking(wake_w, False)
    previous = {sig: signal.signal(sig, lambda *_: stop.append(True))
                for sig in (signal.SIGINT, signal.SIGTERM)}
    old_wakeup = signal.set_wakeup_fd(wake_w)
    poll = select.poll()
    poll.register(wake_r, select.POLLIN)
    reader = None
    if control is not None:
        try:
            reader = ControlReader(control)
            poll.register(control, select.POLLIN)
        except (OSError, ValueError):
            reader = None                      # e.g. a file that cannot be polled
    stdout = sys.stdout.fileno()
    poll.register(stdout, 0)                  # only errors: the reader went away
    host.register(poll)
    ms = SECOND // 1000
    try:
        while not stop:
            due = line.wake_instant()
            timeout = None if due is None else max(0, -(-(due - line.now) // ms))
            for fd, events in poll.poll(timeout):
                if fd == wake_r:
                    with contextlib.suppress(OSError):
                        os.read(wake_r, 512)
                elif fd == stdout:
                    raise StdoutGone
                elif reader is not None and fd == reader.fd:
                    if events & select.POLLIN and reader.read(line):
                        continue
                    poll.unregister(fd)        # end of input: serve on without a console
                    reader = None
                else:
                    host.on_event(fd, events, line, poll)
            out = line.take_ready()
            if out:
                host.send(out, poll)
    except Quit:
        pass
    finally:
        signal.set_wakeup_fd(old_wakeup)
        for sig, handler in previous.items():
            signal.signal(sig, handler)
        os.close(wake_r)
        os.close(wake_w)
        host.close()


def control_fd() -> int | None:
    """Standard input as the control channel, if there is one."""
    try:
        fd = sys.stdin.fileno()
        os.fstat(fd)
    except (OSError, ValueError, AttributeError):
        return None
    return fd
