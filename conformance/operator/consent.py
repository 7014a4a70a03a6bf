"""Whether a run may move something physical, decided here for every entry point (the
suite's run and its fleets, `diff`, `replay`, the pytest plugin).

Only a unit in real time can move a machine: a serial or TCP unit, and an ``exec:``
program serving a port in real time (it may drive one). The embedded emulator (``emu:``)
and a co-simulator in virtual time (an ``exec:`` program whose first line is ``cosim 1``)
move nothing physical and are never asked about.

For a unit that can move, motion is allowed in one of two ways: up front (``--yes``,
``--gve-yes``; a fleet's members once their parent asked), or by the person at the
terminal answering y to "Move this machine?" before the run's first frame that can move
an axis. Where nobody can answer and nothing was allowed up front, the run is refused
before anything is sent (:class:`NoConsent`, one line). An answer other than y refuses
every motion frame of the run (the guard's SafetyStop: those cases COULD-NOT-TEST).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

from conformance.operator.console import Console, confirm_motion
from conformance.targets import Target
from conformance.targets.info import EMULATOR
from conformance.verdicts.quoting import escaped

#: how motion was allowed, as the reports say it (RunMeta.confirmed)
GIVEN = "--yes"
ASKED = "asked"
ASKED_YES = "asked: yes"
ASKED_NO = "asked: refused, nothing moved"


class NoConsent(Exception):
    """Motion would need a yes and nobody can give one: the run is refused, one line."""


def moves(target: Target) -> bool:
    """Whether ``target`` can move something physical: a unit in real time. An ``exec:``
    program not started yet counts as one until its first line says ``cosim 1``."""
    return not target.info.virtual_time


def spec_moves(spec: str) -> bool:
    """:func:`moves` for a target's command-line text, before it is opened (a question
    asked of every target at once must not open their ports)."""
    return spec.partition(":")[0] != EMULATOR


def cannot_ask(flag: str) -> str:
    """Why a run that must ask before moving stops before sending anything."""
    return (f"motion needs a yes and nobody can answer here (no terminal): give {flag} on "
            "an unattended bench")


def what_moves(target: Target, version: str = "", processor_id: str = "") -> list[str]:
    """What the question shows of one unit: who it is, its envelope, destructive tests."""
    axes = ", ".join(f"{a} ±{target.info.max_travel}" for a in target.profile.axes)
    return [f"{target.info.spec}: {escaped(version) or '(no answer to ?)'}, "
            f"Q {escaped(processor_id)}, "
            f"judged as {target.profile.name}",
            f"  envelope (full steps either side of where the run began): {axes}",
            "  destructive tests (J, W, EEPROM writes; EEPROM backed up and restored): "
            + ("ON" if target.info.allow_destructive else "off")]


@dataclass
class Consent:
    """The run's consent to motion: given up front (``yes``) or asked of ``console``.
    ``flag`` is the option that gives it (``--yes``; ``--gve-yes`` in pytest);
    ``answered`` is told how motion was allowed once it is known (the reports')."""

    yes: bool
    console: Console
    flag: str = GIVEN
    answered: Callable[[str], None] = lambda how: None

    def how(self, targets: Sequence[Target]) -> str:
        """How motion is allowed before the run: ``--yes``, ``asked`` (at the first
        move), or "" (nothing physical can move)."""
        if not any(moves(t) for t in targets):
            return ""
        return GIVEN if self.yes else ASKED

    def check(self, targets: Sequence[Target]) -> None:
        """Refuse (NoConsent), before anything is sent, a run on a unit that can move
        when no yes was given up front and nobody can answer the question."""
        self.check_specs([t.info.spec for t in targets if moves(t)])

    def check_specs(self, specs: Sequence[str]) -> None:
        """:meth:`check` for targets not opened yet, by their command-line text."""
        if any(spec_moves(s) for s in specs) and not self.yes and not self.console.interactive:
            raise NoConsent(cannot_ask(self.flag))

    def arm(self, target: Target) -> None:
        """Set the question ``target``'s session asks before its first frame that can
        move an axis (none when motion was allowed up front or nothing can move); a no
        refuses every motion frame of the run."""
        if self.yes:
            return

        def ask() -> bool:
            if not moves(target):             # it turned out to run in virtual time
                return True
            found = target.session.identity
            yes = confirm_motion(self.console, what_moves(
                target, found.get("version", ""), found.get("processor_id", "")))
            self.answered(ASKED_YES if yes else ASKED_NO)
            if not yes:
                self.console.say("  motion refused: cases that move will be COULD-NOT-TEST")
            return yes
        target.session.before_motion = ask

    def ask_once(self, targets: Sequence[Target],
                 identities: Callable[[Target], tuple[str, str]]) -> bool:
        """The question once for several targets before any of them runs (a fleet, whose
        members have no terminal; the controller of a pytest fleet): True when motion
        is allowed. ``identities`` gives each unit's (version, processor ID) known so far."""
        physical = [t for t in targets if moves(t)]
        if not physical or self.yes:
            return True
        yes = confirm_motion(self.console, [line for t in physical
                                            for line in what_moves(t, *identities(t))])
        self.answered(ASKED_YES if yes else ASKED_NO)
        return yes
