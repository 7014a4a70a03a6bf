"""A stand-in unit that follows the Unit contract (docs/architecture.md) and nothing
more, so the line's tests depend on the contract, not on the real unit's internals.

It answers ``0\\r`` to every ``!<addr>...\\r`` frame at the instant the frame's CR is
complete; ``!<addr>W\\r`` additionally schedules ``2\\r`` a fixed delay later (the shape
of an H answer or a watchdog error: something due at ``next_deadline()``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

DELAY_NS = 100_000_000


@dataclass
class FakeProfile:
    name: str = "FAKE"
    default_baud: int = 9600


class FakeUnit:
    def __init__(self, address: int = 0) -> None:
        self.profile = FakeProfile()
        self.address = address
        self.addresses = {address}
        self.emit: Callable[[bytes, int], None] = lambda data, t: None
        self.frame = bytearray()
        self.due: int | None = None
        self.received: list[tuple[bytes, int]] = []      # (frame, instant its CR completed)
        self.advanced: list[int] = []
        self.inputs: dict[int, int] = {}
        self.switches: dict[str, int | None] = {}
        self.powered: list[int] = []
        self.rate_switch: int | None = None      # read at power-on; taken as the rate itself
        self.rate: int | None = None

    def receive(self, data: bytes, t: int, byte_ns: int) -> None:
        for i, byte in enumerate(data):
            self.frame.append(byte)
            if byte == 0x0D:
                frame, self.frame = bytes(self.frame), bytearray()
                self._frame(frame, t + i * byte_ns)

    def _frame(self, frame: bytes, t: int) -> None:
        self.received.append((frame, t))
        if frame[:1] != b"!" or int(frame[1:2]) not in self.addresses:
            return
        self.emit(b"0\r", t)
        if frame[2:3] == b"W":
            self.due = t + DELAY_NS

    def next_deadline(self) -> int | None:
        return self.due

    def advance(self, t: int) -> None:
        self.advanced.append(t)
        if self.due is not None and t >= self.due:
            due, self.due = self.due, None
            self.emit(b"2\r", due)

    def set_input(self, port: int, value: int, t: int) -> None:
        self.inputs[port] = value

    def set_switch(self, axis: str, position: int | None) -> None:
        self.switches[axis] = position

    def set_rate_switch(self, position: int | None) -> None:
        self.rate_switch = position

    def power_on(self, t: int) -> None:
        self.powered.append(t)
        self.rate = self.rate_switch

    def hears(self, baud: int) -> bool:
        return self.rate is None or self.rate == baud

    def snapshot(self, t: int) -> dict:
        return {"address": self.address, "t": t, "inputs": self.inputs}
