"""The scenarios of a host certification: the clean run, whose executed
motion is the baseline, and one run per fault, each at its point of the job.

A scenario is filed under the spec section whose rule it exercises most (8: recovery with
`@` and `>`; 10.1: the full queue; 3: the watchdog; 10.3: interrupt inputs; 2: the link).
Its fault is built from the baseline; a scenario the host's job gives no point for (no
packet, no setting, no interrupt input enabled) is MISSING, with the reason.
"""

from __future__ import annotations

import fnmatch
from collections.abc import Callable
from dataclasses import dataclass

from conformance.host.final_state import Final
from conformance.host.line_faults import (
    DAMAGE,
    AnswerFault,
    Fault,
    FrameFault,
    Interrupt,
    JobPoint,
    QueueFull,
    Restart,
)
from conformance.host.recording import Exchange
from conformance.host.unitview import SETTINGS, VECTORS, Executed
from gve_fixtures.protocol import ErrorCode


@dataclass
class Baseline:
    """What the clean run showed: the motion executed per unit, where it ended, the
    exchanges (the points faults aim at) and the interrupt input the host enabled."""

    executed: dict[int, list[Executed]]
    final: dict[int, Final]
    exchanges: list[Exchange]
    seconds: float
    interrupt: tuple[int, int, int, int] | None = None   # address, port, bit, level

    @property
    def vectors(self) -> int:
        return sum(1 for steps in self.executed.values() for s in steps if s.kind in VECTORS)

    def middle(self, point: str) -> JobPoint | None:
        """The middle exchange of a kind (vector, packet, setting) that the unit took."""
        found = [ex for ex in self.exchanges if point_of(ex) == point]
        if not found:
            return None
        ex = found[len(found) // 2]
        return JobPoint(ex.frame.raw, ex.vectors_before)

    def halfway(self) -> JobPoint | None:
        return JobPoint(b"", max(1, self.vectors // 2)) if self.vectors else None


def point_of(ex: Exchange) -> str | None:
    """Which point of a job an exchange is, when the unit took it (answered 0)."""
    f = ex.parsed
    if ex.code != ErrorCode.OK or f.command is None:
        return None
    if f.command in VECTORS and any(p.lstrip("-0") for p in f.params):
        return "vector"
    if f.command == "*E":
        return "packet"
    return "setting" if f.command in SETTINGS else None


#: how a scenario builds its fault: the fault, or why the job offers no point for it
Build = Callable[[Baseline], "Fault | str"]


@dataclass(frozen=True)
class Scenario:
    name: str
    section: str
    title: str
    build: Build
    info: bool = False            # graded INFO: how the host reacts, no verdict on it

    @property
    def id(self) -> str:
        return f"{self.section}.host.{self.name}"


POINTS = {"vector": "a motion vector", "packet": "a packet's `*E`", "setting": "a setting"}
ABSENT = {"vector": "the host's job sent no vector that got its own answer",
          "packet": "the host sent no packet", "setting": "the host sent no setting"}


def _answer(kind: str, point: str) -> Build:
    def build(b: Baseline) -> Fault | str:
        target = b.middle(point)
        return ABSENT[point] if target is None else AnswerFault(kind, target)
    return build


def _frame(kind: str) -> Build:
    def build(b: Baseline) -> Fault | str:
        target = b.middle("vector")
        return ABSENT["vector"] if target is None else FrameFault(kind, target)
    return build


def _queue_full(b: Baseline) -> Fault | str:
    target = b.halfway()
    return "the host's job sent no vector" if target is None else QueueFull(target)


def _interrupt(b: Baseline) -> Fault | str:
    target = b.halfway()
    if b.interrupt is None or target is None:
        return "the host enabled no interrupt input (SW0/SW1) before its motion"
    address, port, bit, level = b.interrupt
    return Interrupt(target, port, bit, level, address)


def _restart(b: Baseline) -> Fault | str:
    target = b.halfway()
    if target is None:
        return "the host's job sent no vector"
    return Restart(target, next(iter(b.executed)))


_TITLES = {"lost-answer": "the answer to {} is lost",
           "corrupt-answer": "the answer to {} is damaged (a bad checksum in checksum "
                             "mode, a broken byte otherwise)",
           "late-answer": "the answer to {} comes late",
           "noise": "noise comes before the answer to {}"}

SCENARIOS: tuple[Scenario, ...] = (
    Scenario("clean", "2", "the clean line: the host's job, the baseline of the motion",
             lambda b: Fault()),
    *(Scenario(f"{kind}.{point}", "8", _TITLES[kind].format(what), _answer(kind, point))
      for kind in DAMAGE for point, what in POINTS.items()),
    Scenario("queue-full", "10.1", "the queue answers 1 (full) for a while mid-job",
             _queue_full),
    Scenario("lost-frame", "8", "a motion vector never reaches the unit",
             _frame("lost-frame")),
    Scenario("cut-frame", "3", "a motion vector is cut short and the unit's watchdog "
             "answers 2", _frame("cut-frame")),
    Scenario("interrupt", "10.3", "the interrupt input the host enabled trips mid-job, "
             "then is released", _interrupt),
    Scenario("restart", "2", "the unit restarts mid-job (INFO: how the host reacts)",
             _restart, info=True),
)


def select(patterns: list[str] | None) -> list[Scenario]:
    """The scenarios whose name matches a pattern (all when none); the clean run always,
    as every other scenario is judged against it."""
    if not patterns:
        return list(SCENARIOS)
    return [s for s in SCENARIOS if s.name == "clean"
            or any(fnmatch.fnmatchcase(s.name, p) or fnmatch.fnmatchcase(s.id, p)
                   for p in patterns)]
