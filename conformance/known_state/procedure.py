"""The known state a case starts from on a real unit, set by the manuals' rules only and
read back: stopped and at rest, the reset values of what cannot be read, the axes back
where the run began, the counters zeroed. A step the unit refuses, or that does not do
what its rule says, is a FAIL of that rule (:class:`StepFailure`, once a run) and the run
goes on where it safely can; a unit not brought to rest leaves the case COULD-NOT-TEST
(:class:`StepFailed`), naming what was left."""

from __future__ import annotations

from collections.abc import Sequence

from conformance.known_state.failed_steps import Failures, StepFailed
from conformance.known_state.rest import ToRest
from conformance.known_state.way_back import WayBack
from conformance.link.framing import Response
from conformance.link.link import Link
from conformance.link.safety import Guard
from conformance.protocol.wire import is_hex_byte
from gve_fixtures.profile import Profile
from gve_fixtures.protocol import St6


class KnownState:
    """The procedure, its stop (:attr:`rest`), its way back (:attr:`way_back`) and the
    steps that failed in the run (:attr:`failures`)."""

    def __init__(self, profile: Profile, guard: Guard, failures: Failures,
                 problems: list[str]) -> None:
        self.profile = profile
        self.failures = failures
        self.rest = ToRest(profile, guard, self.failures)
        self.way_back = WayBack(profile, guard, self.rest, self.failures, problems)

    def settle(self, link: Link, then: Sequence[str] = ()
               ) -> tuple[str, dict[str, Response | None]]:
        """The rig's hands off (a simulator's rig: inputs and switches as found), stopped
        (:meth:`ToRest.stop`), the reset values of what cannot be read, then the frames
        ``then``. Returns why the unit is not at rest ("" when it is) and the answers to
        the frames after the stop, by frame."""
        if link.rig is not None:
            link.rig.hands_off()
        after = [*self.rest.reset_frames(), *then]
        why, answers = self.rest.stop(link, after)
        return why, dict(zip(after, answers, strict=True))

    def bring(self, link: Link, tell: Sequence[str] = ()) -> None:
        """Stopped and at rest (read back), the reset values, the axes back where the run
        began, the counters zeroed (read back); :class:`StepFailed` when the unit could
        not be brought there. The hand wheel's reset mode `&` switches the MPG on (M114
        13.6.8), which holds the axes (RUN without INTA) wherever the unit's active
        configuration enables it — also after a case's EEPROM 06 was put back, on a unit
        that reads its EEPROM at reset only: then it is turned off again (`Y-`)."""
        left, _ = self.settle(link, ["PF"])       # where the axes are, for the way back
        if left:
            raise StepFailed(left)
        if self.rest.has_mpg():
            st6 = link.send("SR6")
            if st6 is not None and st6.ok and st6.values and is_hex_byte(st6.values[0]) \
                    and int(st6.values[0], 16) & (St6.RUN | St6.INTA) == St6.RUN:
                link.send("Y-")
        spindle = self.profile.spindle
        if spindle is not None:
            # the spindle off, as after reset (M114 13.5 "O0,FF - Výstup vypnutý"): `O0`
            # need not reset the setting of `!7V`, which a case or sequence may have left
            link.send("V0", address=spindle.address)
        returned, there = self.way_back.go_back(link, read=False)
        link.tell(["N", "PF", *tell])
        self.way_back.zero(link, returned, there)
