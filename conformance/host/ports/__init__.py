"""Where the host meets the relay, one small module per kind of port (as pyserial's URL
handlers are): a pseudo-terminal (pty.py, the default), a TCP port served as pyserial's
``socket://`` (tcp.py), or a real serial device behind a null-modem cable (device.py).

Every port offers the same few operations to the relay (:class:`HostPort`)."""

from __future__ import annotations

from typing import Protocol

from conformance.host.ports import device, pty, tcp

__all__ = ["HostPort", "open_port"]


class HostPort(Protocol):
    def fileno(self) -> int:
        """Readable when the host sent bytes (or, on TCP, when it connects)."""
        ...

    def read(self) -> bytes:
        """Every byte the host has sent so far (never blocks; b"" when none)."""
        ...

    def write(self, data: bytes) -> int:
        """Give the host bytes; returns how many it took (never blocks)."""
        ...

    def settings(self) -> str | None:
        """The host's port settings (``115200 8N1``) where the port shows them."""
        ...

    @property
    def name(self) -> str:
        """What the host opens: a path, or a pyserial URL (``socket://...``)."""
        ...

    def close(self) -> None: ...


def open_port(spec: str, baud: int) -> HostPort:
    """``pty`` (a new pseudo-terminal), ``tcp:HOST:PORT`` or a device path; a
    ValueError with one line when it cannot be opened."""
    try:
        if spec == "pty":
            return pty.PtyPort(baud)
        if spec.startswith("tcp:"):
            host, _, port = spec[4:].rpartition(":")
            if not port.isdigit() or not 0 <= int(port) <= 65535:
                raise ValueError(f"--port {spec!r}: expected tcp:HOST:PORT, PORT 0..65535")
            return tcp.TcpPort(host or "127.0.0.1", int(port))
        return device.DevicePort(spec, baud)
    except OSError as err:
        raise ValueError(f"--port {spec}: {err.strerror or err}") from None
