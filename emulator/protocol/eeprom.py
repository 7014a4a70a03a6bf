"""The unit's EEPROM (spec 10.6): 256 bytes, optionally backed by an image file.

The image survives J and power cycles. The file given must be an image: a regular file
of exactly the EEPROM's size, or absent (then it is created with the defaults); anything
else — a FIFO, a device, a directory, a file of another size — is refused before it is
opened (:class:`EepromPlaceError`), so that nothing waits on a FIFO, reads a device
without end, or cuts a file that was never an image. Every write replaces the file atomically: the
new image goes to ``<image>.tmp`` next to it (flushed and fsynced) and is renamed over
the image, with the signals that could interrupt it held back meanwhile, so a write
leaves either the old or the new image and no temporary file. A place where the image
cannot be written is refused when the EEPROM is created (:class:`EepromPlaceError`);
a write that fails later keeps the byte in the unit and says so once on stderr.
"""

from __future__ import annotations

import os
import signal
import stat
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
            found = self._image()
            if found is not None:
                self.data[:] = found
            self._replace(self._temporary(), probe=found is not None)
        except OSError as err:
            raise self._refused(f"{err.strerror or err}") from None

    def _image(self) -> bytes | None:
        """The image the file holds (None: there is no file), looked at with ``stat``
        before it is opened; EepromPlaceError when the file is no image."""
        assert self.path is not None
        try:
            found = os.stat(self.path)
        except FileNotFoundError:
            return None
        size = len(self.data)
        if not stat.S_ISREG(found.st_mode):
            raise self._refused(f"{_kind(found.st_mode)}, not an image file")
        if found.st_size != size:
            raise self._refused(f"{found.st_size} bytes, an image is {size}")
        fd = os.open(self.path, os.O_RDONLY | os.O_NONBLOCK)   # never waits, even if
        try:                                                   # swapped meanwhile
            stored = os.read(fd, size + 1)
        finally:
            os.close(fd)
        if len(stored) != size:
            raise self._refused(f"it changed while read, an image is {size} bytes")
        return stored

    def _refused(self, why: str) -> EepromPlaceError:
        return EepromPlaceError(f"cannot keep the EEPROM image in {self.path}: {why}")

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


def _kind(mode: int) -> str:
    """What a file that is no regular file is (for the refusal)."""
    if stat.S_ISDIR(mode):
        return "a directory"
    if stat.S_ISFIFO(mode):
        return "a FIFO"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "a device"
    return "a socket" if stat.S_ISSOCK(mode) else "a special file"
