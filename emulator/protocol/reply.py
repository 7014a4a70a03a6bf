"""What a command handler gives back to the unit, which turns it into response bytes.

- a list of strings: the values of an answer with code 0;
- :class:`Answer`: a code with values (``*E`` answers ``code,k`` also when it fails);
- :class:`Deferred`: an answer due later (H and W answer when the motion has stopped);
- :class:`Plain`: bytes sent as they are and never remembered (``>``, ``J``);
- ``None``: no answer at all (``*S``).

A refusal is raised as :class:`emulator.protocol.params.CommandError` instead.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass


@dataclass(frozen=True)
class Answer:
    code: int
    values: list[str]


@dataclass(frozen=True)
class Deferred:
    """An answer due at ``instant``; ``finish(instant)`` gives its code and values."""

    instant: int
    finish: Callable[[int], tuple[int, list[str]]]


@dataclass(frozen=True)
class Plain:
    data: bytes


Reply = list[str] | Answer | Deferred | Plain | None
