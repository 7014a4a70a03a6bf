"""What a port offers besides bytes, as typed interfaces: a test rig's hands on the unit
(docs/rig.md) and, in virtual time, the line's clock. The embedded emulator's ``gve://``
port and a co-simulator's port offer both as their ``line``; the suite reaches them
through :func:`line_of` only, never by the attribute."""

from __future__ import annotations

from typing import Protocol, runtime_checkable


@runtime_checkable
class Rig(Protocol):
    """A test rig's hands: the unit's inputs, its home switches, its power, and what
    the unit drives (outputs, the spindle)."""

    def set_input(self, port: int, value: int, address: int | None = None) -> None: ...

    def set_switch(self, axis: str, position: int | None, address: int | None = None
                   ) -> None: ...

    def power_on(self, address: int | None = None) -> None: ...

    def outputs(self, address: int | None = None) -> int: ...

    def spindle(self, address: int | None = None) -> int: ...

    def state(self, address: int | None = None) -> dict: ...


class VirtualLine(Rig, Protocol):
    """A line in virtual time: its clock moves only when asked (or by the bytes written),
    and its rig acts at the clock's instant."""

    baud: int

    @property
    def now(self) -> int: ...               # ns since the line's origin

    def advance(self, seconds: float) -> None: ...

    def advance_to(self, t: int) -> None: ...


@runtime_checkable
class VirtualPort(Protocol):
    """A serial port whose line runs in virtual time."""

    line: VirtualLine


def line_of(port: object) -> VirtualLine:
    """The virtual-time line ``port`` offers (TypeError: a port in real time)."""
    if not isinstance(port, VirtualPort):
        raise TypeError(f"{type(port).__name__} runs in real time: it offers no line")
    return port.line
