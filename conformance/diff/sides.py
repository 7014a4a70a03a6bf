"""One side of a differential run: a target's link for one example, the frames sent
through the run's session (its guard judges every one before it goes out), and the
clock the two sides share.

The target leads; the reference follows it in time. When both are in virtual time
(the embedded emulator against a mutant of itself, or a co-simulator) each step starts
on both at the same instant: the one behind is advanced to the other (exact). When the
target runs in real time, the reference (virtual) is advanced, before each step, to the
instant the target has reached since the example began.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

from conformance.link.framing import HostFramer, Response, parse_response
from conformance.link.link import Link
from conformance.link.virtual import line_of
from conformance.targets import Session, Target
from conformance.targets.session import EmuSession
from conformance.verdicts.verdict import CouldNotTest


@dataclass
class RoundTrip:
    """One frame on one side: what went out, what came back and when (ns since the
    example began, on that side's clock)."""

    sent: bytes
    answer: bytes
    sent_at: int
    received_at: int
    response: Response | None
    lines: int = 1

    @property
    def code(self) -> int | None:
        return None if self.response is None else self.response.code


class Side:
    """A target as one side of the comparison."""

    def __init__(self, target: Target, session: Session | None = None) -> None:
        self.target = target
        self.session = session
        self.link: Link | None = None
        self._origin = 0
        #: why the rig stopped answering (its input steps are left out from then on)
        self.rig_lost: str | None = None
        #: where the rig saw the axes at the latest power-on, where the guard's envelope
        #: was re-centred and the known state brings them back (None: from 0)
        self._physical: list[int] | None = None
        #: where the rig saw the axes of the unit the simulator keeps (a 1-tuple; None:
        #: not read yet)
        self._kept_physical: tuple[list[int] | None] | None = None

    @property
    def virtual(self) -> bool:
        return self.target.info.virtual_time

    @property
    def real(self) -> bool:
        """A unit that lives on between examples (its session's known state, not a
        fresh unit): a real one, or a co-simulator."""
        return self.session is not None and self.session.real

    @property
    def has_rig(self) -> bool:
        return self.link is not None and self.link.rig is not None and self.rig_lost is None

    def open(self, tell: Sequence[str] = (), meanwhile: Callable[[], None] | None = None
             ) -> Link:
        """A link in the known state for a new example: on the emulator a fresh unit (and
        a session of its own, so one example's silences do not count in the next); on a
        real unit the run's session's known state, ``tell`` the frames sent first on it,
        ``meanwhile`` work done while a co-simulator runs the known state's frames told
        ahead (Session.open_link)."""
        if self.virtual and not self.target.info.real:
            self._physical = None
            self.session = EmuSession(self.target, self.session.interrupts if self.session
                                      else None)
        elif self.session is None:
            self.session = self.target.begin()
        self.link = self.session.open_link(tell=tell, meanwhile=meanwhile)
        self._origin = self.link.now
        return self.link

    def open_powered(self, *, kept: bool = False,
                     meanwhile: Callable[[], None] | None = None) -> Link | None:
        """A co-simulator's link begun at its power-on through the rig in place of the
        known state (RealSession.open_powered; with ``kept``, the unit powered on first
        kept where the simulator keeps a state, and restored for the next), and where its
        rig then sees
        the axes, from which the sequence's physical positions count (a fresh reference's
        count from 0): read once for the unit kept, since a restored one is that unit;
        None where the target cannot be begun so (the known state then). ``meanwhile``:
        work of the caller's done while the simulator powers the unit on (done whenever
        a power-on is asked for, taken or not)."""
        if self.session is None:
            self.session = self.target.begin()
        if not getattr(self.session, "powers_on", False):
            return None
        link = self.session.open_powered(kept=kept, meanwhile=meanwhile)
        if link is None:
            return None
        self.link = link
        self._origin = link.now
        if self.session.restored and self._kept_physical is not None:
            self._physical = self._kept_physical[0]
            return link
        self._physical = None
        state = self.rig_state()
        seen = None if state is None else state.get("physical")
        self._physical = list(seen) if _counts(seen) else None
        self._kept_physical = (self._physical,)
        return link

    def age(self, seconds: float) -> None:
        """Virtual time: let a fresh unit stand for ``seconds`` and begin the example
        there (a unit with a history: no dwell counted from its power-on)."""
        if self.virtual:
            line_of(self.link.port).advance(seconds)
            self._origin = self.link.now

    @property
    def now(self) -> int:
        """Nanoseconds since the example began."""
        return self.link.now - self._origin

    def catch_up(self, t: int) -> None:
        """Virtual time: advance to ``t`` (ns since the example began) if behind."""
        if self.virtual and t > self.now:
            line = line_of(self.link.port)
            line.advance_to(line.now + (t - self.now))

    def exchange(self, data: bytes, *, lines: int = 1, answer: bool = True,
                 stall: tuple[int, float] | None = None, body: str | None = None,
                 meanwhile: Callable[[], None] | None = None,
                 like: Side | None = None) -> RoundTrip:
        """Send a frame's bytes (through the guard: SafetyStop when refused) and take
        what comes back: its answer (``answer``), else whatever arrives while the
        answer's bytes would have taken. ``body``: the frame's command, when known (it
        decides how long an answer may take). ``meanwhile``: work of the caller's that
        a port which sends a write before its read (a co-simulator's) does while the
        target runs the frame, between the two (any other port: not done here).
        ``like``: the side whose window it is listened to for (the reference for the
        target's: its guard's window for a W or an H may be shorter than the reference's
        own, and two sides listened to for different times differ in when they went
        quiet); else its own (:meth:`awaited`)."""
        link = self.link
        if body is None:
            body = _body(data, link.checksums)
        if stall is not None:
            link.inject("host", "delay", at=stall[0], seconds=stall[1])
        link.send_raw(data)
        sent_at = link.wrote_at - self._origin
        timeout = (like or self).awaited(data, body, answer)
        if answer:
            launch = getattr(link.port, "launch", None)
            if meanwhile is not None and launch is not None:
                launch(timeout)
                meanwhile()
            r = link.read_response(timeout, lines, summed=link.summed_after(body))
            back = r.raw if r is not None else b""
        else:
            back = link.wait(timeout)
            r = parse_response(back, summed=link.checksums) if back else None
        return RoundTrip(data, back, sent_at, self.now, r, lines)

    def awaited(self, data: bytes, body: str, answer: bool = True) -> float:
        """Seconds a frame's answer is awaited (``answer``); for a frame that is due none,
        how long the line is listened to after it (an answer's bytes would be over)."""
        link = self.link
        if answer:
            return link.answer_timeout(body, len(data))
        return link.byte_seconds(len(data) + 64) + 0.005

    def wait(self, seconds: float, meanwhile: Callable[[], None] | None = None) -> bytes:
        """Let ``seconds`` pass; ``meanwhile``: work of the caller's done while a port
        that takes a wait ahead waits (Link.wait)."""
        return self.link.wait(seconds, meanwhile=meanwhile)

    def set_input(self, port: int, value: int) -> bool:
        """Set a rig input; False (and the rig lost) when the rig does not do it: a rig
        that does not answer is a rig that is not there."""
        try:
            self.link.rig.set_input(port, value)
        except CouldNotTest as err:
            self.rig_lost = str(err)
            return False
        return True

    def rig_act(self, words: str) -> bool:
        """Another act of the rig's hands (docs/rig.md): `power-on` (the host then takes
        the checksum mode off, as the reset state has it, spec 9) or `switch AXIS POS|none`,
        POS counted from where this side's axes stood when the example began; False (and
        the rig lost) when the rig does not do it."""
        word, *rest = words.split()
        try:
            if word == "power-on":
                self.link.rig.power_on()
                self.link.checksums = False
            else:
                axis, where = rest
                i = self.target.profile.axes.index(axis)
                self.link.rig.set_switch(axis, None if where == "none"
                                         else int(where) + self._origin_of(i))
        except CouldNotTest as err:
            self.rig_lost = str(err)
            return False
        return True

    def _origin_of(self, axis: int) -> int:
        """Where the rig sees ``axis`` stand when an example begins: at the latest
        power-on, or where the run began (the known state brings the axes back there)."""
        if self._physical is not None and axis < len(self._physical):
            return self._physical[axis]
        found = getattr(self.session, "_rig_origin", None) if self.real else None
        return found.get(axis, 0) if isinstance(found, dict) else 0

    def state_next(self) -> None:
        """The rig's `state` is read once the next frame is answered: a port that takes
        commands ahead (a co-simulator's) sends it with that frame."""
        ask_next = getattr(self.link.port, "ask_next", None) if self.has_rig else None
        command = getattr(self.link.rig, "state_command", None) if ask_next else None
        if command is not None:
            ask_next(command())

    def rig_state(self) -> dict | None:
        """What the rig sees of the unit now (docs/rig.md `state`); None (and the rig
        lost) when it does not say."""
        try:
            state = self.link.rig.state()
        except CouldNotTest as err:
            self.rig_lost = str(err)
            return None
        seen = state.get("physical") if isinstance(state, dict) else None
        if self._physical is not None and _counts(seen) and len(seen) == len(self._physical):
            state = {**state, "physical": [a - b for a, b in zip(seen, self._physical,
                                                                   strict=True)]}
        return state

    def close_example(self) -> None:
        """Take what is still on its way (an answer after the last frame); on a real unit
        put back the EEPROM bytes the example wrote, as after a case (the reference of the
        next example is fresh)."""
        if self.link is not None:
            self.link.settle(final=True)
        if self.session is not None:
            self.session.after_case()

    def write_eeprom(self, image: dict[int, int]) -> None:
        """Virtual time: give the reference these EEPROM bytes (a real unit's, as found)
        before the example begins."""
        for address, value in sorted(image.items()):
            self.link.send("EW%02X,%02X" % (address, value))


def _body(data: bytes, summed: bool) -> str:
    frames = HostFramer().frames(data)
    if not frames:
        return ""
    bodies = frames[-1].bodies(summed)
    return bodies[0] if bodies else ""


def _counts(seen: object) -> bool:
    """Whether a rig's `physical` is a list of counts (anything else is not subtracted
    from: compared, or not, as it came)."""
    return isinstance(seen, list) and all(
        isinstance(v, int) and not isinstance(v, bool) and abs(v) < 2**62 for v in seen)
