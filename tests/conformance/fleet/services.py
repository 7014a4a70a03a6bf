"""Processes the fleet tests start and stop: emulated units on TCP ports and a Redis
server on a free loopback port, each waited for on a condition with a deadline."""

from __future__ import annotations

import selectors
import shutil
import socket
import subprocess
import sys
import time
from pathlib import Path

from tests.processes import stop


class Service:
    """A process started for a test, stopped (terminate, then kill) by :meth:`stop`."""

    def __init__(self, argv: list[str], **popen) -> None:
        self.proc = subprocess.Popen(argv, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                     stderr=subprocess.STDOUT, text=True, **popen)

    def readline(self, timeout: float) -> str:
        sel = selectors.DefaultSelector()
        sel.register(self.proc.stdout, selectors.EVENT_READ)
        if not sel.select(timeout):
            raise TimeoutError(f"{self.proc.args[0]} printed nothing in {timeout} s")
        return self.proc.stdout.readline().strip()

    def stop(self) -> None:
        stop(self.proc)
        self.proc.stdout.close()


def tcp_unit(*args: str) -> tuple[Service, str]:
    """``python -m emulator ARGS --tcp 127.0.0.1:0``: the process and its ``HOST:PORT``
    (the first line it prints)."""
    unit = Service([sys.executable, "-m", "emulator", *args, "--tcp", "127.0.0.1:0"])
    try:
        kind, _, where = unit.readline(20.0).partition(" ")
    except TimeoutError:
        unit.stop()
        raise
    assert kind == "tcp", (kind, where)
    return unit, where


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def redis_server(folder: Path, deadline: float = 20.0) -> tuple[Service, str]:
    """A Redis server of its own on a free loopback port: the process and its URL.
    Raises LookupError, saying why, when none can be had."""
    binary = shutil.which("redis-server")
    if binary is None:
        raise LookupError("redis-server is not installed (Debian: apt-get install redis-server)")
    try:
        from redis import Redis, RedisError
    except ImportError:
        raise LookupError("the redis package is not installed (the dev extra has it)") from None
    port = free_port()
    server = Service([binary, "--port", str(port), "--bind", "127.0.0.1", "--save", "",
                      "--appendonly", "no", "--dir", str(folder)], cwd=folder)
    client = Redis(host="127.0.0.1", port=port, socket_connect_timeout=1)
    end = time.monotonic() + deadline
    while True:
        try:
            client.ping()
            return server, f"redis://127.0.0.1:{port}/0"
        except RedisError:
            if server.proc.poll() is not None or time.monotonic() > end:
                server.stop()
                raise LookupError(f"redis-server did not answer on port {port}") from None
            time.sleep(0.05)    # polling the server's readiness, up to the deadline
