"""Where a pair's two sides begin a sequence: both in the known state (the target's
session's, the reference a fresh unit given the target's history), or both from the
reset state where the target is a co-simulator in virtual time; and, for a unit that
lives on between sequences, the prelude both are sent first and the index each reads
there, which the sequence's index is compared from (index_base.py)."""

from __future__ import annotations

from conformance.diff.index_base import IndexBase
from conformance.diff.sides import Side
from conformance.diff.steps import FILL, FRAME, RIG, Step
from conformance.diff.timing import Timing
from conformance.link.link import Link
from conformance.link.liveness import TargetNotResponding
from conformance.link.stops import SafetyStop
from gve_fixtures.profile import Profile
from gve_fixtures.protocol import SECOND, ErrorCode

#: real time: how long the fresh reference stands before a sequence
AGE_SECONDS = 1.0
#: a unit that lives on between sequences: what both sides are sent first (the index read
#: between two `SR0`, the same history for `>`); told ahead with the known state's last
PRELUDE = ("SR0", "@", "SR0")


class Start:
    """How one pair's sequences begin."""

    def __init__(self, target: Side, reference: Side, profile: Profile,
                 timing: Timing) -> None:
        self.target = target
        self.reference = reference
        self.profile = profile
        self.timing = timing
        self._eeprom_changes: dict[int, int] | None = None   # real target: see prelude
        self._reference_index = 0          # the reference's index read in the prelude

    def known(self) -> IndexBase:
        """Both sides in the known state: the target's session's (its proof read back on
        a unit that lives on), the reference a fresh unit given the target's history;
        the index compared from where each side read it in the prelude."""
        real = self.target.real
        # the reference's beginning needs nothing more of the target's (its EEPROM as
        # found is known): done while a co-simulator runs the known state's frames
        alone = real and self.target.session is not None and self.eeprom_known()
        self.target.open(tell=PRELUDE if real else (),
                         meanwhile=self.begin_reference if alone else None)
        if not alone:
            self.begin_reference()
        self.timing.begin()
        return self.prelude() if real else IndexBase()

    def powered(self, kept: bool) -> bool:
        """Both sides from the reset state the manuals state (spec 9 [M]): a co-simulator
        in virtual time powered on through its rig (its restart waited out on the suite's
        clock: no wall time; RealSession.open_powered; ``kept``: restored from its first
        unit powered on), the reference a fresh unit standing as long since its start,
        given the target's EEPROM as found. Nothing is read back: a power-on that left
        something behind shows in the sequence's first answers, a finding of its own.
        False where the target is not begun so (a real unit, a real-time simulator, a
        rig that refuses `power-on`): the known state then."""
        # the fresh reference is made while the simulator powers its unit on
        if self.target.open_powered(kept=kept, meanwhile=self.reference.open) is None:
            return False
        self.same_eeprom()
        self.reference.age(self.target.session.since_power_on / SECOND)
        self.timing.begin()
        return True

    def begin_reference(self) -> None:
        """The reference in its known state, a fresh unit; where the target lives on
        between examples, the reference's part of the prelude (:meth:`prelude`)."""
        self.reference.open()
        if self.target.real:
            self.same_eeprom()
            self.reference.age(AGE_SECONDS)
            self._reference_index = _index_read(self.reference)

    def prelude(self) -> IndexBase:
        """A unit that lives on between examples (a real one, a co-simulator) is not
        reset by the known state: its index is read on both sides and compared from
        there; and give `>` the same history on both (`SR0`, answered 0,00 by both). The
        reference, a fresh unit, first stands a while: the real one's last motion ended
        long ago (a vector right away would otherwise wait the dwell T on one side only),
        and the target's too: the known state may have moved its axes back just before,
        so the sequence begins once the longest dwell T after that has passed (waited
        after the reads, which the known state told a co-simulator ahead with its last).
        The reference's part is done as it begins (:meth:`begin_reference`)."""
        index = _index_read(self.target)
        self.target.wait(self.profile.range("T").hi / 1000)
        return IndexBase((index - self._reference_index) % 256)

    def eeprom_known(self) -> bool:
        """Whether :meth:`same_eeprom` sends nothing to the target (its bytes as found
        are read already, or it has none)."""
        return self._eeprom_changes is not None or "ER" not in self.profile.commands

    def same_eeprom(self) -> None:
        """A real unit's EEPROM holds its own bytes, not a fresh unit's: the reference
        gets the bytes the target was found with (read once; the session puts back what
        an example wrote) where they differ from its own."""
        if self.target.session is None or "ER" not in self.profile.commands:
            return
        if self._eeprom_changes is None:
            found = self.target.session.eeprom_as_found()
            image = self.profile.eeprom          # a fresh unit's: erased, with defaults
            self._eeprom_changes = {a: v for a, v in found.items()
                                    if image.defaults.get(a, image.erased) != v}
        self.reference.write_eeprom(self._eeprom_changes)


def left_summing(before: list[Step], started_at_power_on: bool, link: Link) -> bool:
    """Whether a power-on left the checksum mode on, where a disagreement came after
    ``before`` (the steps before it) with no frame since the latest power-on (the
    sequence's start at one, or the rig's): asked as a session asks a unit it finds (`?`
    without its checksum refused 4, with it taken: spec 6)."""
    powered = [i for i, step in enumerate(before) if step.kind == RIG
               and step.body == "power-on"]
    since = before[powered[-1] + 1:] if powered else before
    if not (powered or started_at_power_on) or any(
            step.kind in (FRAME, FILL) for step in since):
        return False
    try:
        plain = link.send("?", checksum=False)
        summed = plain is not None and plain.code == ErrorCode.SYNTAX and \
            link.send("?", checksum=True)
    except (SafetyStop, TargetNotResponding):
        return False
    return bool(summed and summed.ok)


def _index_values(side: Side) -> list[str]:
    """What a side's `@` answers in the prelude (its second frame), as written."""
    r = side.link.send_each(PRELUDE)[1]
    return [] if r is None else list(r.values)


def _index_read(side: Side) -> int:
    """The index a side reads in the prelude (0 when unread or not a decimal number)."""
    values = _index_values(side)
    try:
        return int(values[0]) if len(values) == 1 else 0
    except ValueError:
        return 0
