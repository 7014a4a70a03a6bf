"""A known-state step that failed: a FAIL of the rule the step relies on, once a run, with
the frames that led there."""

from __future__ import annotations

from dataclasses import dataclass, replace

from conformance.link.link import Link
from conformance.verdicts.verdict import CouldNotTest


@dataclass(frozen=True)
class StepFailure:
    """A known-state step the unit refused, or that did not do what its rule says. The
    machinery relies on the manuals' rules only (spec preamble), so this is a failure of
    that rule, reported once a run under the rule's section with the evidence, not a
    wall of COULD-NOT-TEST nor a FAIL of the case that was about to begin."""

    rule: str          # the rule of fixtures/rules.toml the step relies on
    step: str          # the step, for the result's ID: "delete", "zero", "return-move"
    what: str
    observed: str
    expected: str
    #: the frames that led there: the traffic before the known state (the case's, the
    #: sequence's) and the known state's own, as transcript lines
    led_there: tuple[str, ...] = ()


#: the most lines of the traffic before a known state kept with a step that failed in it
LED_THERE_LINES = 60


class StepFailed(CouldNotTest):
    """The known state could not be set for a case (a step failed, or the unit is not at
    rest): the case is COULD-NOT-TEST with the reason."""


class Failures:
    """The known-state steps that failed in a run, each rule once, and the link whose
    traffic came before the known state being set (its last lines lead there)."""

    def __init__(self) -> None:
        self.booked: list[StepFailure] = []
        self._untaken = 0                           # failures not yet taken by the run
        self.before: Link | None = None             # the link before the known state's

    def take(self) -> list[StepFailure]:
        """The failures booked since the last call, for the run to report as FAILs of
        their rules."""
        new = self.booked[self._untaken:]
        self._untaken = len(self.booked)
        return new

    def book(self, link: Link, failure: StepFailure) -> None:
        """Book ``failure`` (a rule already failed this run keeps its first evidence), its
        evidence read on ``link``: not where an answer on it did not belong to its frame
        (answered twice, or late), since then no answer read there is surely its frame's
        (that FAILs the case whatever the tag)."""
        if not link.violations and all(f.rule != failure.rule for f in self.booked):
            before = [] if self.before is None else \
                [rec.line() for rec in self.before.log[-LED_THERE_LINES:]]
            led = [*before, "# the known state", *link.transcript_lines()] if before \
                else link.transcript_lines()
            self.booked.append(replace(failure, led_there=tuple(led)))
