"""Bringing a real unit to rest by the manuals' rules only: `H` in the mode the unit is
in (a packet a case left open closed first), checksums off, the hand wheel and the
interrupts off, a `K` left given back with its `R`, `D`, read back with `SR6`; what
cannot be read set to the reset state; where `D` does not leave the unit at rest, the
remainder run out, else `J` where destructive commands are allowed."""

from __future__ import annotations

from collections.abc import Sequence

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
from conformance.known_state.failed_steps import Failures, StepFailure
from conformance.known_state.limits import known_axis_limits
from conformance.link.account import Spent
from conformance.link.answer_time import LONGEST_ANSWER_S
from conformance.link.framing import Response
from conformance.link.link import MARGIN, Link
from conformance.link.safety import MOTION, Guard
from conformance.protocol.parse import parse_text
from gve_fixtures.profile import Profile
from gve_fixtures.protocol import SECOND, ErrorCode, St6
from gve_fixtures.transcript import HOST, UNIT, Record

#: the `*E` that closes a packet left open: -1 is no count of members, so it is refused
PACKET_CLOSER = "*E-1"
#: the `*E` that closes it on a unit that refused the first as a malformed frame and kept
#: the packet open: a count every reading takes, and one no member is committed by (none
#: taken: nothing to commit; some: their count differs)
SURE_CLOSER = "*E0"
#: how often the known state asks whether a halted remainder `D` did not delete has run
#: out: a remainder whose axes did not move for that long is stuck (then `H` again)
RUN_OUT_POLL_S = 1.0
#: how often a frame answered "not yet" is sent again, each time once SR6 shows RUN = 0
NOT_YET_TRIES = 3


class ToRest:
    """The stop and what it relies on (`H`, "not yet" waited out, the position read), for
    the known state, Ctrl-C and the restorations alike; a step the unit refuses or that
    does not do what its rule says is booked in ``failures``."""

    def __init__(self, profile: Profile, guard: Guard, failures: Failures) -> None:
        self.profile = profile
        self.guard = guard
        self.failures = failures

    def halt(self, link: Link, timeout: float | None = None, *,
              urgent: bool = False) -> Response | None:
        """`H` in the mode the unit is in: refused (4) or unanswered in the mode the link
        believes, it is sent in the other. A packet that may be open is closed first;
        ``urgent`` (Ctrl-C, a unit gone quiet) sends `H` first all the same, and closes
        the packet and sends `H` again only when that `H` went unanswered."""
        closed = not urgent and self._close_packet(link, timeout)
        r = link.send("H", timeout=timeout)
        if r is None and urgent and self.guard.packet_open:
            closed = self._close_packet(link, timeout)
            r = link.send("H", timeout=timeout)
        if r is None and closed:
            # H taken as a member: the closer was refused as a malformed frame and the
            # packet kept open (a reading of spec 7); a count every reading takes ends it
            self._close_packet(link, timeout, SURE_CLOSER)
            r = link.send("H", timeout=timeout)
        if r is None or r.code == ErrorCode.SYNTAX:
            other = link.send("H", checksum=not link.checksums, timeout=timeout)
            if other is not None and other.ok:
                link.checksums = not link.checksums
                return other
        return r

    def _close_packet(self, link: Link, timeout: float | None = None,
                      closer: str = PACKET_CLOSER) -> bool:
        """Close a packet a case may have left open, in a way every reading ends one:
        that `H`, `@`, `>` and `J` close it is our reading [D]; only `*E` is sure to
        (spec 7). Its count is no count, so every unit refuses it and the packet's members
        are not committed by it (a unit that committed them as they arrived already has:
        the guard books them as maybe committed). Unanswered in the mode the link believes
        (a failing member), it is sent in the other. ``closer``: the `*E` sent
        (:data:`SURE_CLOSER` whether or not the guard believes a packet open); returns
        whether one was."""
        if "*E" not in self.profile.commands or not (
                self.guard.packet_open or closer == SURE_CLOSER):
            return False
        r = link.send(closer, timeout=timeout)
        if r is None:
            other = link.send(closer, checksum=not link.checksums, timeout=timeout)
            if other is not None:
                link.checksums = not link.checksums
        return True

    def reset_frames(self) -> list[str]:
        """What cannot be read, set to the reset state (spec 9)."""
        p, r = self.profile, self.profile.reset
        table = {"O0": "O0,%02X" % r.outputs, "XM": f"XM{r.XM}", "VN": "VK" if r.VK else "VN",
                 "VL": "VL" + ",".join(str(v) for v in known_axis_limits(p))}
        frames = [body for name, body in table.items() if name in p.commands]
        frames += [f"V{r.V}", f"A{r.A}", f"B{r.B}", f"${r.dollar}", f"T{r.T}"]
        if self.has_mpg():
            frames.append(f"Y{p.mpg.reset_mode}")
        if p.microstep:
            frames += [f"M{p.microstep.reset_mode}", f"M{p.microstep.reset_current}"]
        return frames

    def has_mpg(self) -> bool:
        return self.profile.mpg is not None and "Y" in self.profile.commands

    def position(self, link: Link) -> dict[int, int]:
        r = link.send("PF")
        if r is None or not r.ok or len(r.values) < 3:
            return {}
        try:
            return {i: r.dec(i) for i in range(min(3, len(self.profile.axes)))}
        except AssertionError:
            return {}

    def stop(self, link: Link, then: Sequence[str] = ()) -> tuple[str, list[Response | None]]:
        """`H`, checksums off, the hand wheel (MPG) off, interrupts off (ST0..ST5 = 00), the
        save of a `K` the last case left given back with `R` (the manual's inverse of `K`:
        the queue back to its size), then `D`: the queue empty and ST6 clear (an input
        still enabled would set INTA again at once), read back with `SR6`; then the frames
        ``then``. Only the manuals' rules: no second `K`, no `R` with nothing kept. An MPG
        that EEPROM 06 made effective holds the axes (the unit is moving): `D` and EEPROM
        writes would be refused and the INTA of `H` outlive the stop, so it is off until
        the reset frames set its reset mode again. Returns why the unit is not at rest
        ("" when it is: :meth:`_at_rest`) and the answers to ``then``."""
        mpg = ["Y-"] if self.has_mpg() else []
        held = self.guard.keep_held and not self.guard.interrupts.stopped
        # R moves nothing on a unit that keeps the manual (the save holds INTA with any
        # queue), but a unit that does not may run it: R only where the envelope takes it.
        # The halted vectors H left are deleted first: a unit may refuse R while they hold
        # RUN ("nelze použít za chodu" read as RUN = 1); what R gives back is deleted after
        give_back = ["D", "R"] if held and self.guard.fits("R") else []
        frames = [*mpg, *(f"SW{n},00" for n in range(6)), *give_back, "D", "SR6"]
        if not link.checksums and not self.guard.packet_open:
            link.tell(["H", *frames, *then])       # H as _halt sends it, then the rest
        halt = self.halt(link)
        if link.checksums:
            link.send("%-", checksum=True)
        answers = link.send_each(frames)
        if halt is not None and halt.code is not None and not halt.ok:
            self.failures.book(link, self._halt_refused(halt, link.checksums))
        why = self._at_rest(link, halt, answers[-2], answers[-1])
        if held and not give_back and not why:
            why = self._keep_not_given_back(link)
        if give_back and not why and not taken(answers[-3]):
            why = self._give_back(link, answers[-3])
        return why, link.send_each(then)

    def _give_back(self, link: Link, restored: Response | None) -> str:
        """`R` was not taken after `D` left the unit at rest: "not yet" (7, 1) is asked
        again once `SR6` shows RUN = 0, and what it gives back deleted; refused at rest
        (read back before and after) it is a FAIL of `R`'s rule. Returns why the unit is
        not at rest ("" when it is)."""
        if not_yet(restored):
            restored = self.when_idle(link, "R", restored)
            deleted, st6 = link.send_each(["D", "SR6"])
            if not rests(st6):
                return ("the unit is not at rest after the known state gave back a KEEP: R "
                        f"{shown(restored)}, D {shown(deleted)}, SR6 reads {shown(st6)}"
                        + left(st6))
        if not taken(restored):
            self.failures.book(link, StepFailure(
                "10.5.restore.exact", "restore", "R gives back the save of the K the unit "
                "accepted (not while moving)", f"R {shown(restored)} at rest", "R accepted"))
        return ""

    def await_idle(self, link: Link, seconds: float | None = None) -> Response | None:
        """`SR6` until it shows RUN and STOP clear (spec 10.3 [M]: RUN = 0 is nothing
        running), at most ``seconds`` (:meth:`_idle_seconds` unless given): that answer,
        else None (RUN stayed set, or `SR6` was not answered). Halted vectors (RUN with
        INTA) do not end by waiting: None at once."""
        def done(r: Response) -> bool:
            return not hex_ok(r) or not bits(r) & (St6.RUN | St6.STOP) \
                or bool(bits(r) & St6.INTA)
        st6 = link.poll("SR6", done, self._idle_seconds() if seconds is None else seconds)
        idle = st6 is not None and hex_ok(st6) and not bits(st6) & (St6.RUN | St6.STOP)
        return st6 if idle else None

    def _idle_seconds(self) -> float:
        """The longest a unit may hold RUN once what it was asked is done: the longest
        T dwell a reader may give a vector with no motion (`L0,0,0`), or the longest stop
        the envelope allows, and the line's margin."""
        return (self.profile.range("T").hi / 1000 + 2 * self.guard.stop_seconds()
                + 2 * MARGIN)

    def when_idle(self, link: Link, body: str, first: Response | None = None
                   ) -> Response | None:
        """``body`` (`N`, `N<axis>`, `M`, `R`, `EW`, the return `L`: refused while a
        vector runs) until it is answered otherwise than "not yet" (7, 1), each time
        again once `SR6` shows RUN = 0 (:meth:`await_idle`): a unit may hold RUN for a
        T dwell after the `L0,0,0` the known state waits with, or read the manuals'
        "za chodu" as RUN = 1. ``first``: its answer already had (else it is sent now).
        The last answer."""
        r = link.send(body) if first is None else first
        for _ in range(NOT_YET_TRIES):
            if not not_yet(r):
                return r
            if self.await_idle(link) is None:
                return r                # RUN stayed set, or vectors halted: not again
            r = link.send(body)
        return r

    def _halt_refused(self, halt: Response, summed: bool) -> StepFailure:
        """`H` answered otherwise than 8. `H` has no parameter: where the unit took `%+`
        (``summed``: the link believes the mode on) and refused `H` with 4, the code of a
        bad or missing checksum, in both framings (:meth:`halt` tries each), it refuses
        frames summed as the manual sums them (a FAIL of that rule); any other answer is a
        FAIL of `H`'s own."""
        if halt.code == ErrorCode.SYNTAX and summed:
            return StepFailure(
                "6.checksum.sum", "halt", "H framed as the manual states, summed from ! up "
                "to and including the comma in checksum mode and plain otherwise, is taken",
                f"H {shown(halt)} in either framing", "8")
        return StepFailure("10.cmd.halt-answer", "halt", "H is answered 8",
                           f"H {shown(halt)}", "8")

    def _at_rest(self, link: Link, halt: Response | None, deleted: Response | None,
                 st6: Response | None) -> str:
        """Whether the stop left the unit at rest: RUN, STOP and INTA clear in ST6, as `D`
        after `H` leaves it (spec 10.4 [M]: `D` is for the rest of the queue after an
        interruption, and clears ST6). Where an INTA that `H` set outlives `D`, `D` did
        not do what its rule says (a FAIL of that rule); the unit is then brought to rest by
        other means (:meth:`_to_rest`) and ST6 is read again. Returns why the unit is not
        at rest ("" when it is)."""
        if rests(st6):
            return ""
        if not bits(st6) & St6.INTA and halt is not None:
            # moving or braking with no stop of H's left: given the longest stop to end
            st6 = link.poll("SR6", rests, 2 * self.guard.stop_seconds() + 2) or st6
            if rests(st6):
                return ""
        if halt is not None and halt.ok and hex_ok(st6) and bits(st6) & St6.INTA:
            # what the bookkeeping took for deleted may still be queued: no position read
            # tells where the axes rest until the unit shows rest
            self.guard.doubt_rest()
            failure = self._not_deleted(link, halt, deleted, st6)
            if failure is None:
                return ""
            self.failures.book(link, failure)
            if not self.guard.interrupts.stopped:
                st6 = self._to_rest(link)
                if rests(st6):
                    return ""
        if st6 is not None and not st6.ok:
            return ("the unit refuses the known state's frames, its status unread: H "
                    f"{shown(halt)}, SR6 {shown(st6)}")
        return f"the unit is not at rest after the known state: SR6 reads {shown(st6)}" \
            + left(st6)

    def _not_deleted(self, link: Link, halt: Response, deleted: Response | None,
                     st6: Response) -> StepFailure | None:
        """`D` after `H` left INTA. Refused as busy (7: "nelze použít za chodu"), the
        unit may still be running in a sense the manuals allow: a reader may count the
        T dwell after its last vector as running and let `H` leave it to end (M54 T:
        "prodleva mezi nenavazujícími vektory", up to the longest T). So `SR6` is read
        until RUN and STOP clear, for at most the longest T (:meth:`_dwell_seconds`: a
        held remainder keeps RUN all along), and `D` is sent again: taken, and ST6 then
        clear, the unit is at rest and nothing failed (None). `PF` read before and after
        that wait tells whether the axes moved after `H` was answered: the frame that
        answers only once they stopped (spec 2) did not — the `W` that last set them
        moving where one did (spec 10: under simplex `H` cannot meet a `W` run that
        answered when done; whether `H` stops one is the manuals' silence), else `H`.
        At rest, `D` still refused once the longest T is over, or `D` not clearing ST6,
        broke `D`'s own rule. The wait is for what ST6 shows, not a time of the suite's:
        however short the suite's other waits, `D` is asked again only after it."""
        evidence = f"H {shown(halt)}, D {shown(deleted)}, SR6 {shown(st6)}"
        if deleted is not None and deleted.code is not None \
                and deleted.code & 7 == ErrorCode.BUSY:
            first = self.position(link)
            waited = link.poll("SR6", lambda r: not hex_ok(r) or not bits(r) & (
                St6.RUN | St6.STOP), self._dwell_seconds())
            then = self.position(link)
            evidence += (f", SR6 {'still RUN' if waited is None else shown(waited)} "
                         f"within the longest T, PF {shown_counters(first)} then "
                         f"{shown_counters(then)}")
            before = self.failures.before
            last = ("", False) if before is None else _last_motion(before.log)
            # a W whose answer never came: whether H stops its run is the manuals' silence
            if first and then and first != then and last != ("W", False):
                if last == ("W", True):
                    return StepFailure(
                        "10.cmd.reference", "reference", "W answers only when its run is "
                        "over: the axes still moved after its answer (and H's)", evidence,
                        "the axes at rest from W's answer on")
                return StepFailure("10.4.halt.ramp", "halt", "H answers only when the unit "
                                   "has stopped", evidence, "the axes at rest from H's answer on")
            again = link.send("D")
            evidence += f", D again {shown(again)}"
            if taken(again):
                st6 = link.send("SR6")
                if rests(st6):
                    return None
                evidence += f", SR6 {shown(st6)}"
        return StepFailure(
            "10.4.delete", "delete", "D after H (the unit stopped, the longest T dwell over) "
            "empties the queue and clears ST6", evidence,
            "D 0, then SR6 with RUN, STOP and INTA clear")

    def _dwell_seconds(self) -> float:
        """The longest a unit stopped by `H` may still count itself running: the longest
        T dwell a reader may let run after its last vector, and the line's margin."""
        return self.profile.range("T").hi / 1000 + 2 * MARGIN

    def _keep_not_given_back(self, link: Link) -> str:
        """A `K` the last case left whose save `R` would give back beyond the envelope:
        `J` where destructive commands are allowed (the save gone with the reset); else
        why the unit is not in the known state (its queue takes one `L` only)."""
        if self._may_reset():
            return "" if rests(self._reset(link)) else "the unit is not at rest after J"
        return ("a KEEP the last case left is still held (its R would give back a queue "
                "the envelope cannot take), and J, which would clear it, needs "
                "--allow-destructive")

    def _may_reset(self) -> bool:
        return self.guard.allow_destructive and "J" in self.profile.commands

    def _reset(self, link: Link) -> Response | None:
        """`J` (the reset state: ST6 = 00, spec 9 [M]), the hand wheel off and what cannot
        be read set again; the position read at rest before and after (J zeroes the
        counters: only a read before tells where the axes stand), ST6 read back."""
        self.position(link)
        link.send("J")
        link.wait(self.profile.restart_ms / 1000 + MARGIN, Spent.MANUAL)
        link.send_each([*(["Y-"] if self.has_mpg() else []), *self.reset_frames()])
        self.position(link)
        return link.send("SR6")

    def _to_rest(self, link: Link) -> Response | None:
        """At rest by other means than `D`, by the manuals' rules: `G`, and the remainder
        runs out (:meth:`_run_out`; the axes end where the bookkeeping knows them); still
        not at rest, `J` where destructive commands are allowed (the reset state, ST6 = 00:
        spec 9 [M]) and what cannot be read set again. Then the position read at rest,
        and ST6 again."""
        if not self._run_out(link):
            self.halt(link)
        self.position(link)
        st6 = self.await_idle(link) or link.send("SR6")
        return st6 if rests(st6) or not self._may_reset() else self._reset(link)

    def _run_out(self, link: Link) -> bool:
        """`G`, then `L0,0,0` until it is taken (0, INTA clear: nothing queued or running,
        spec 10.1 [M]) while `PF` shows the axes moving, as long as the remainder could take
        at the slowest `V` (the reset frames put XM back); whether it was taken."""
        link.send("G")
        # how far the axes may still go: the queue, or where a D the unit answered 0
        # without deleting anything left the bookkeeping's doubt
        travel = max(s.hi - s.lo for s in self.guard.envelope.reach())
        seconds = 2 * travel / self.profile.range("V").lo + 2 * self.guard.stop_seconds() + 2
        deadline = link.now + min(seconds, LONGEST_ANSWER_S) * SECOND
        before: list[str] | None = None
        while link.now < deadline:
            r = link.send("L0,0,0")
            if r is not None and r.ok and not r.inta:
                return True
            here = link.send("PF")
            moved = None if here is None else here.values
            if moved == before:                    # a second and not a step: stuck
                return False
            before = moved
            link.wait(RUN_OUT_POLL_S, Spent.MOTION)
        return False


def _last_motion(log: Sequence[Record]) -> tuple[str, bool]:
    """The class (spec 10) of the last frame in ``log`` that could start motion ("" none),
    and whether the unit answered it."""
    answered = False
    for rec in reversed(log):
        if rec.direction == UNIT:
            answered = True
        elif rec.direction == HOST and rec.data.startswith(b"!"):
            key = parse_text(rec.data[1:].decode("latin-1").rstrip("\r\n")).key
            if key in MOTION:
                return key, answered
            answered = False
    return "", False
