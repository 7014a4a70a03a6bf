"""Fault injection at the byte and frame level.

A fault transforms the bytes of one frame (host side: what the suite sends) or of one
response (unit side: what comes back, on emulator targets). Each injector is a pure
function from bytes to a list of (bytes, pause-before-seconds) pieces, so it can be
tested alone and applied the same way on any target.
"""

from __future__ import annotations

from dataclasses import dataclass, field

KINDS = ("drop", "drop-byte", "corrupt", "truncate", "delay", "split")
DIRECTIONS = ("host", "unit")

Pieces = list[tuple[bytes, float]]


@dataclass
class Fault:
    direction: str
    kind: str
    params: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.direction not in DIRECTIONS:
            raise ValueError(f"fault direction must be one of {DIRECTIONS}")
        if self.kind not in KINDS:
            raise ValueError(f"fault kind must be one of {KINDS}")

    def apply(self, data: bytes) -> Pieces:
        return INJECTORS[self.kind](data, **self.params)


def drop(data: bytes) -> Pieces:
    return []


def drop_byte(data: bytes, at: int = 1) -> Pieces:
    at = min(at, len(data) - 1)
    return [(data[:at] + data[at + 1:], 0.0)]


def corrupt(data: bytes, at: int = 2, xor: int = 0x01) -> Pieces:
    at = min(at, len(data) - 1)
    return [(data[:at] + bytes([data[at] ^ xor]) + data[at + 1:], 0.0)]


def truncate(data: bytes, keep: int = 3) -> Pieces:
    return [(data[:keep], 0.0)]


def delay(data: bytes, at: int = 3, seconds: float = 0.2) -> Pieces:
    return [(data[:at], 0.0), (data[at:], seconds)]


def split(data: bytes, size: int = 2, seconds: float = 0.001) -> Pieces:
    return [(data[i:i + size], seconds if i else 0.0) for i in range(0, len(data), size)]


INJECTORS = {"drop": drop, "drop-byte": drop_byte, "corrupt": corrupt,
             "truncate": truncate, "delay": delay, "split": split}
