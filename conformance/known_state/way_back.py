"""The axes back where the run began and the counters zeroed, read back: the end of the
known state (and the axes' part of the restorations). Where the frames no longer tell
where the axes are, a test rig's eyes locate them, when the rig has eyes."""

from __future__ import annotations

from conformance.known_state.answers import (
    bits,
    hex_ok,
    left,
    not_yet,
    rests,
    shown,
    shown_counters,
    taken,
)
from conformance.known_state.failed_steps import Failures, StepFailed, StepFailure
from conformance.known_state.rest import ToRest
from conformance.link.account import Spent
from conformance.link.framing import Response
from conformance.link.link import Link
from conformance.link.safety import Guard
from conformance.verdicts.verdict import CouldNotTest
from gve_fixtures.profile import Profile
from gve_fixtures.protocol import SECOND, St6

#: during the way back, a frame at least every this many of the unit's restart times
#: (spec 2: about 2 s), so that a restart on the way is heard
WATCH = 0.25


class WayBack:
    """The return move and the counters zeroed; what it cannot do safely goes into
    ``problems`` (the session report's), a step the unit breaks into ``failures``."""

    def __init__(self, profile: Profile, guard: Guard, rest: ToRest, failures: Failures,
                 problems: list[str]) -> None:
        self.profile = profile
        self.guard = guard
        self.rest = rest
        self.failures = failures
        self.problems = problems
        #: where a test rig with eyes saw the axes as found (docs/rig.md, `physical`)
        self.rig_origin: dict[int, int] | None = None

    def go_back(self, link: Link, *, read: bool = True) -> tuple[str, dict[int, int]]:
        """Move the axes back to where the run began (known exactly only at rest; the
        counters read first unless ``read`` is False: just read). After a restart that
        left them anywhere on their trail, a test rig's eyes locate them first, when the
        rig has eyes. Returns the frame that moved them ("" none) and the counters read
        at the end."""
        read_now = self.rest.position(link) if read else {}
        envelope = self.guard.envelope
        if None in envelope.position():
            self.relocate(link)
        if envelope.unheld:
            axes = ", ".join(sorted({self.profile.axes[i] for i in envelope.unheld}))
            why = (f"position counters ({axes}) set with N<axis> read back other values at "
                   "rest: taken for counters that do not hold them, the axes where the "
                   "frames put them")
            if why not in self.problems:
                self.problems.append(why)
            envelope.unheld.clear()
        here = envelope.position()
        back = [0 if h is None else -int(h) for h in here]
        if not any(back):
            return "", read_now
        speed = self.profile.reset.V
        body = "L" + ",".join(str(b) for b in back)
        if not self.guard.fits(body):
            # counters read beyond where any frame let the axes go (a unit whose counters
            # wrap): the read wins for safety, so the axes stay and motion beyond is refused
            why = (f"the axes could not go back to where the run began: {body} would leave "
                   "the envelope (the counters read contradict the frames sent)")
            if why not in self.problems:
                self.problems.append(why)
            return "", read_now
        r = self.rest.when_idle(link, body)
        if r is None or not r.ok:
            self._return_refused(link, body, r)
            return "", self.rest.position(link)
        cruise = max(abs(b) for b in back) / speed        # the least the way back takes
        seconds = self._return_seconds(body)
        # watched as long as it takes with its ramps at the reset acceleration (A in
        # 1000 steps/s²), so that the first L0,0,0 after it is taken (one poll, not two)
        self._watch(link, cruise + speed / (self.profile.reset.A * 1000))
        if link.poll("L0,0,0", lambda r: r.ok, seconds) is None:
            self.failures.book(link, StepFailure(
                "10.1.queue.wait-idiom", "return-move", "the return move, an L from rest, "
                f"ends: L0,0,0 is then taken (within {seconds:.1f} s)",
                f"{body} 0, L0,0,0 not taken", "L0,0,0 answered 0"))
            raise StepFailed("the return to where the run began did not end in time")
        return body, self.rest.position(link)

    def _return_refused(self, link: Link, body: str, r: Response | None) -> None:
        """The return move answered otherwise than 0: at rest (ST6 read back) that is a
        FAIL of `L` from rest (spec 10.1 [M]) and the axes stay where they are (the
        envelope still bounds every frame); else the case cannot begin."""
        st6 = link.send("SR6") if r is not None else None
        if not rests(st6):
            raise StepFailed(f"the return to where the run began ({body}) answered "
                             f"{shown(r)}, SR6 then {shown(st6)}" + left(st6))
        self.failures.book(link, StepFailure(
            "10.1.queue.line-alone", "return-move", "the return move, an L with nothing "
            "queued or running (the unit read back at rest), is accepted",
            f"{body} {shown(r)}, SR6 {shown(st6)}", f"{body} 0"))

    def _watch(self, link: Link, seconds: float) -> None:
        """Let ``seconds`` of the way back pass with a frame at least every WATCH of the
        unit's restart time: a unit that restarts on the way (spec 2: deaf for about
        2 s) leaves one unanswered, which the guard weighs with the read at the end."""
        step = WATCH * self.profile.restart_ms / 1000
        end = link.now + round(seconds * SECOND)
        while link.now < end:
            link.wait(min(step, (end - link.now) / SECOND), Spent.MOTION)
            if link.now < end:
                link.send("SR6")

    def relocate(self, link: Link) -> None:
        """Where the axes are when the frames no longer tell (a restart left them anywhere
        on their trail, a `W` at a switch the suite cannot see): a test rig's eyes (a
        simulator's `physical`, docs/rig.md) tell, when the rig has them; the guard then
        lets motion go out again."""
        if self.rig_origin is None:
            return
        now = self.rig_physical(link)
        counters = self.rest.position(link)
        if now is None or len(counters) < min(3, len(self.profile.axes)):
            return
        self.guard.locate({a: now[a] - self.rig_origin[a] for a in now}, counters)

    def rig_physical(self, link: Link) -> dict[int, int] | None:
        """Where the rig sees each axis (`physical`, counter units since the simulator
        started), or None: no rig, or one without eyes, or a `state` without them."""
        state = getattr(link.rig, "state", None)
        if state is None:
            return None
        try:
            seen = state().get("physical")
        except (CouldNotTest, AttributeError):
            return None
        axes = len(self.profile.axes)
        if not isinstance(seen, list) or len(seen) < axes or \
                not all(type(v) is int and abs(v) < 2**31 for v in seen[:axes]):
            return None
        return dict(enumerate(seen[:axes]))

    def zero(self, link: Link, returned: str = "", there: dict[int, int] | None = None
              ) -> None:
        """`N`, read back with `PF`: every counter 0 (spec 10 [M]); answered "not yet"
        (7: a unit may hold RUN a T dwell after the `L0,0,0` that ended the return move)
        it is sent again once `SR6` shows RUN = 0. Where `N` did not zero them at rest, a
        FAIL of its rule, and `N<axis>0` where the unit has it; counters still elsewhere
        leave the case COULD-NOT-TEST (cases judge positions from 0). ``returned``: the
        return move just ended by `L0,0,0`, ``there``: `PF` right after it (axes that
        moved on from there broke the wait idiom: :meth:`_returning`)."""
        zeroed = link.send("N")
        if returned and not_yet(zeroed):
            st6 = link.send("SR6")
            if not rests(st6):
                self._returning(link, returned, there, zeroed, st6)
        zeroed = self.rest.when_idle(link, "N", zeroed)
        with self.guard.unmoved():                 # at rest: a counter read is no motion
            here = self.rest.position(link)
        if taken(zeroed) and here and not any(here.values()):
            return                                 # taken: nothing runs (7 if RUN = 1)
        st6 = link.send("SR6")
        if not rests(st6):
            raise StepFailed(f"the unit is not at rest after the known state: N answered "
                             f"{shown(zeroed)}, SR6 reads {shown(st6)}" + left(st6))
        self.failures.book(link, StepFailure(
            "10.cmd.zero", "zero", "N zeroes every axis counter (the unit at rest)",
            f"N {shown(zeroed)}, PF {shown_counters(here)}", "N 0, PF 0 on every axis"))
        names = self.profile.axes
        setters = [f"N{a}0" for a in names[:3] if f"N{a}" in self.profile.commands]
        if setters:
            for body in setters:
                self.rest.when_idle(link, body)
            with self.guard.unmoved():
                here = self.rest.position(link)
            if here and not any(here.values()):
                return
        raise StepFailed(f"the position counters could not be zeroed (N answered "
                         f"{shown(zeroed)}, PF then {shown_counters(here)}): the cases judge "
                         "positions from 0")

    def _returning(self, link: Link, body: str, there: dict[int, int] | None,
                   zeroed: Response | None, st6: Response | None) -> bool:
        """RUN still set after the return move ``body`` was ended by `L0,0,0`, answered
        0 only once everything before it has finished (spec 10.1 [M]): its end is awaited
        by `SR6` (spec 10.3 [M]). RUN alone is no evidence (a unit may hold it for a T
        dwell after `L0,0,0`, a normal vector to a reader of "program považuje za normální
        vektor"); axes at rest elsewhere than `PF` read them right after that answer are:
        the move still ran, a FAIL of the wait idiom's rule. Whether the unit came to
        rest."""
        if not hex_ok(st6) or not bits(st6) & St6.RUN:
            return False
        rested = link.poll("SR6", rests, self._return_seconds(body)) is not None
        if rested and there:
            with self.guard.unmoved():              # at rest: a counter read is no motion
                then = self.rest.position(link)
            if then and then != there:
                self.failures.book(link, StepFailure(
                    "10.1.queue.wait-idiom", "return-move", "L0,0,0 after the return move "
                    "answers 1 until the move has finished, then 0: the axes no longer "
                    "move once it is answered 0",
                    f"{body} 0, L0,0,0 0, PF {shown_counters(there)}, then N {shown(zeroed)}, "
                    f"SR6 {shown(st6)}, and at rest PF {shown_counters(then)}",
                    "the axes where PF read them once L0,0,0 was answered 0"))
        return rested

    def _return_seconds(self, body: str) -> float:
        """The longest the return move ``body`` (an `L` at the reset V) may take."""
        cruise = max(abs(int(v)) for v in body[1:].split(",")) / self.profile.reset.V
        return cruise * 2 + 2 * self.guard.stop_seconds() + 2
