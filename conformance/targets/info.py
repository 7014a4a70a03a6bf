"""What a case knows of its target: the scheme, the options and how it is graded. Below
``targets`` and ``case`` alike, so that a target can describe itself without knowing what
a case is."""

from __future__ import annotations

from dataclasses import dataclass

#: the scheme of the embedded emulator: a fresh unit in virtual time for every link
EMULATOR = "emu"


@dataclass(frozen=True)
class TargetInfo:
    kind: str                  # emu, serial, tcp, exec
    spec: str                  # as given on the command line
    virtual_time: bool
    has_rig: bool
    allow_destructive: bool
    max_travel: int
    #: graded by the project's decisions: a failed `[D]` check FAILs (the reference
    #: emulator; another target only when the run says --strict)
    strict: bool = False

    @property
    def real(self) -> bool:
        """Whether the unit outlives a link (a unit, or a simulator the suite reaches or
        starts): it is guarded, put into the known state and restored. The embedded
        emulator gives a fresh unit to every link, so nothing of it needs protecting."""
        return self.kind != EMULATOR


def is_emulator_spec(spec: str) -> bool:
    """Whether a target's command-line text names the embedded emulator (before it is
    parsed: a question asked of every target at once must not open their ports)."""
    return spec.partition(":")[0] == EMULATOR
