"""The unit's EEPROM (spec 10.6): 256 bytes, optionally backed by an image file.

The image survives J and power cycles. Every write replaces the file atomically (a
temporary file, flushed and fsynced, then renamed over the image), so a crash in the
middle of a write leaves either the old or the new image, never a torn one.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path


class Eeprom:
    def __init__(self, defaults: bytes, path: str | Path | None = None) -> None:
        self.path = Path(path) if path is not None else None
        self.data = bytearray(defaults)
        if self.path is not None and self.path.exists():
            stored = self.path.read_bytes()
            self.data[: len(stored)] = stored[: len(self.data)]

    def read(self, address: int, size: int = 1) -> bytes:
        return bytes(self.data[address:address + size])

    def write(self, address: int, data: bytes) -> None:
        self.data[address:address + len(data)] = data
        if self.path is not None:
            self._save()

    def _save(self) -> None:
        assert self.path is not None
        folder = self.path.parent
        fd, tmp = tempfile.mkstemp(prefix=self.path.name + ".", dir=folder)
        try:
            with os.fdopen(fd, "wb") as f:
                f.write(self.data)
                f.flush()
                os.fsync(f.fileno())
            os.replace(tmp, self.path)
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise
