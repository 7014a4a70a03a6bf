"""The unit's EEPROM (spec 10.6): 256 bytes, optionally backed by an image file.

The image survives J and power cycles. Every write replaces the file atomically: the
new image goes to ``<image>.tmp`` next to it (flushed and fsynced) and is renamed over
the image, with the signals that could interrupt it held back meanwhile, so a write
leaves either the old or the new image and no temporary file. A place where the image
cannot be written is refused when the EEPROM is created (:class:`EepromPlaceError`);
a write that fails later keeps the byte in the unit and says so once on stderr.
"""

from __future__ import annotations

import os
import signal
import sys
from pathlib import Path

#: signals held back while an image is replaced
_HELD = {signal.SIGINT, signal.SIGTERM, signal.SIGHUP, signal.SIGQUIT}


class EepromPlaceError(ValueError):
    """The image file cannot be read or written where it was asked for."""


class Eeprom:
    def __init__(self, defaults: bytes, path: str | Path | None = None) -> None:
        self.path = Path(path) if path is not None else None
        self.data = bytearray(defaults)
        self._warned = False
        if self.path is None:
            return
        try:
            if self.path.exists():
                stored = self.path.read_bytes()
                self.data[: len(stored)] = stored[: len(self.data)]
            self._replace(self._temporary(), probe=True)
        except OSError as err:
            raise EepromPlaceError(
                f"cannot keep the EEPROM image in {self.path}: {err.strerror or err}") from None

    def read(self, address: int, size: int = 1) -> bytes:
        return bytes(self.data[address:address + size])

    def write(self, address: int, data: bytes) -> None:
        self.data[address:address + len(data)] = data
        if self.path is None:
            return
        try:
            self._replace(self._temporary())
        except OSError as err:
            if not self._warned:
                print(f"gve emulator: the EEPROM image {self.path} was not written "
                      f"({err.strerror or err}); the unit keeps the bytes", file=sys.stderr)
                self._warned = True

    def _temporary(self) -> Path:
        assert self.path is not None
        return self.path.with_name(self.path.name + ".tmp")

    def _replace(self, tmp: Path, probe: bool = False) -> None:
        """Write the image to ``tmp`` and rename it over the image (``probe``: only show
        that this can be done here, removing ``tmp`` again)."""
        assert self.path is not None
        held = signal.pthread_sigmask(signal.SIG_BLOCK, _HELD)
        try:
            try:
                fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
                try:
                    os.write(fd, self.data)
                    os.fsync(fd)
                finally:
                    os.close(fd)
                if not probe:
                    os.replace(tmp, self.path)
            finally:
                tmp.unlink(missing_ok=True)      # gone already after the rename
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, held)
