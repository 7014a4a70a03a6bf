"""A host port with no host behind it: it never sends and takes every answer. For driving
the relay in process, the host's frames fed to it directly (the benchmark, tests)."""

from __future__ import annotations

import os


class SilentPort:
    """Never readable (its fileno is a pipe nothing writes to); every answer taken."""

    name = "(in process)"

    def __init__(self) -> None:
        self._r, self._w = os.pipe()

    def fileno(self) -> int:
        return self._r

    def read(self) -> bytes:
        return b""

    def write(self, data: bytes) -> int:
        return len(data)

    def settings(self) -> None:
        return None

    def close(self) -> None:
        os.close(self._r)
        os.close(self._w)
