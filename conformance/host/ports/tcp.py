"""A TCP port the host reaches as pyserial's ``socket://HOST:PORT``; one host at a time
(a second connection is closed at once). Port 0 picks a free port."""

from __future__ import annotations

import contextlib
import socket


class TcpPort:
    def __init__(self, host: str, port: int) -> None:
        self.listener = socket.create_server((host, port))
        self.listener.setblocking(False)
        self.host, self.port = host, self.listener.getsockname()[1]
        self.name = f"socket://{self.host}:{self.port}"
        self.conn: socket.socket | None = None

    def fileno(self) -> int:
        return (self.conn or self.listener).fileno()

    def read(self) -> bytes:
        if self.conn is None:
            with contextlib.suppress(BlockingIOError):
                conn, _ = self.listener.accept()
                conn.setblocking(False)
                conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
                self.conn = conn
            return b""
        try:
            data = self.conn.recv(65536)
        except BlockingIOError:
            return b""
        except OSError:
            data = b""
        if not data:                      # the host hung up: wait for the next one
            self.conn.close()
            self.conn = None
        return data

    def write(self, data: bytes) -> int:
        if self.conn is None:
            return len(data)              # nobody listens: the bytes are gone
        try:
            return self.conn.send(data)
        except BlockingIOError:
            return 0
        except OSError:
            return len(data)

    def settings(self) -> None:
        return None

    def close(self) -> None:
        for s in (self.conn, self.listener):
            if s is not None:
                with contextlib.suppress(OSError):
                    s.close()
