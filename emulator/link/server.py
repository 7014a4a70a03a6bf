"""Serving a line in real time on a pseudo-terminal or a TCP port.

One loop waits (select) for bytes from the host, control lines on standard input, or
the next instant a unit has something to do (an H answer, the watchdog, a restart),
and writes every byte that is due to the host. SIGINT/SIGTERM end it cleanly.
"""

from __future__ import annotations

import contextlib
import os
import selectors
import signal
import socket
import sys
import termios
import tty
from typing import TextIO

from emulator.link.control import Quit, handle
from emulator.link.line import SECOND, Line

IDLE = 0.05    # seconds between checks when nothing is scheduled


class Server:
    def __init__(self, line: Line, control: TextIO | None = None) -> None:
        self.line = line
        self.control = control
        self.sel = selectors.DefaultSelector()
        self.running = True

    def stop(self, *_: object) -> None:
        self.running = False

    def _timeout(self) -> float:
        nxt = [x for x in (self.line.next_deadline(),
                           self.line._rx[0][0] if self.line._rx else None) if x is not None]
        if not nxt:
            return IDLE
        return min(IDLE, max(0.0, (min(nxt) - self.line.now) / SECOND))

    def _control(self) -> None:
        assert self.control is not None
        text = self.control.readline()
        if not text:                          # EOF: the server goes on without a console
            self.sel.unregister(self.control)
            return
        try:
            answer = handle(self.line, text)
        except Quit:
            self.running = False
            return
        if answer is not None:
            print(answer, flush=True)

    def loop(self, on_data, write) -> None:
        """``on_data(key)`` reads the host's bytes; ``write(bytes)`` sends to the host."""
        for sig in (signal.SIGINT, signal.SIGTERM):
            signal.signal(sig, self.stop)
        if self.control is not None:
            try:
                self.sel.register(self.control, selectors.EVENT_READ, "control")
            except (PermissionError, OSError, ValueError):
                self.control = None          # e.g. /dev/null: no console, serve anyway
        while self.running:
            for key, _ in self.sel.select(self._timeout()):
                if key.data == "control":
                    self._control()
                else:
                    on_data(key)
            out = self.line.take_ready()
            if out:
                write(out)


def serve_pty(line: Line, control: TextIO | None) -> None:
    master, slave = os.openpty()
    tty.setraw(slave)
    attrs = termios.tcgetattr(slave)
    attrs[3] &= ~termios.ECHO
    termios.tcsetattr(slave, termios.TCSANOW, attrs)
    print(os.ttyname(slave), flush=True)
    server = Server(line, control)
    server.sel.register(master, selectors.EVENT_READ, "host")

    def on_data(key) -> None:
        try:
            data = os.read(master, 4096)
        except OSError:
            return
        if data:
            line.write(data)

    def write(data: bytes) -> None:
        os.write(master, data)

    try:
        server.loop(on_data, write)
    finally:
        os.close(master)
        os.close(slave)


def serve_tcp(line: Line, host: str, port: int, control: TextIO | None) -> None:
    listener = socket.create_server((host, port), reuse_port=False)
    listener.setblocking(False)
    print(f"tcp {host}:{listener.getsockname()[1]}", flush=True)
    server = Server(line, control)
    server.sel.register(listener, selectors.EVENT_READ, "listen")
    client: list[socket.socket] = []

    def on_data(key) -> None:
        if key.data == "listen":
            conn, _ = listener.accept()
            if client:                       # one host at a time
                conn.close()
                return
            conn.setblocking(False)
            conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            client.append(conn)
            server.sel.register(conn, selectors.EVENT_READ, "host")
            return
        conn = client[0]
        try:
            data = conn.recv(4096)
        except OSError:
            data = b""
        if data:
            line.write(data)
        else:
            server.sel.unregister(conn)
            conn.close()
            client.clear()

    def write(data: bytes) -> None:
        if client:
            with contextlib.suppress(OSError):
                client[0].sendall(data)

    try:
        server.loop(on_data, write)
    finally:
        for conn in client:
            conn.close()
        listener.close()


def stdin_or_none() -> TextIO | None:
    try:
        os.fstat(sys.stdin.fileno())
    except (OSError, ValueError):
        return None
    return sys.stdin
