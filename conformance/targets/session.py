"""The run-wide session on one target: one per target per run.

It owns what must hold for the whole run on one unit, across links, cases and Hypothesis
examples:

- the :class:`~conformance.link.safety.Guard` every link of the run shares (the motion
  envelope in physical steps, the destructive guard, Ctrl-C, the count of unanswered
  frames), whose interface it offers (:meth:`Session.check`, :meth:`Session.check_raw`,
  :meth:`Session.accepted`) to whoever sends frames by other means;
- the unit as found (:meth:`start`, before the first case): its identity (`?`, `Q`),
  its checksum mode, ST0..ST5, where the axes are, and — when destructive commands are
  allowed — every EEPROM byte, before the run's first EEPROM write;
- the known state a case starts from (:meth:`open_link`): `H`, `D`, the reset values of
  what cannot be read, the axes back where the run began, counters zeroed — by the
  manuals' rules only, and read back (ST6 at rest, the counters at 0): a step the unit
  refuses, or that does not do what its rule says, is a FAIL of that rule
  (:class:`StepFailure`, once a run) and the run goes on where it safely can; a unit not
  brought to rest leaves the case COULD-NOT-TEST, naming what was left;
- Ctrl-C (:meth:`emergency_stop`: `H`, then `D`) and the restorations
  (:meth:`finish`): EEPROM and status words put back and verified by reading back, the
  checksum mode as found, what cannot be read set to the reset state; what could not be
  restored goes into :attr:`report` as a problem.

On the embedded emulator every link is a fresh unit: nothing to protect or restore; its
session (:class:`EmuSession`) still carries Ctrl-C and the count of unanswered frames. A
real unit's (:class:`RealSession`) does all of the above; :func:`open_session` picks one.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterator, Sequence
from dataclasses import asdict, dataclass, field, replace
from typing import Any, Protocol

from conformance.known_state import known_axis_limits
from conformance.link.account import Spent, TimeAccount
from conformance.link.framing import HostFramer, Response, frame, readable
from conformance.link.interrupts import Interrupted, Interrupts
from conformance.link.link import MARGIN, Link
from conformance.link.safety import (
    LONGEST_ANSWER_S,
    MOTION,
    EmulatorGuard,
    Guard,
    SafetyStop,
    TargetNotResponding,
)
from conformance.protocol.parse import parse_text
from conformance.protocol.wire import is_hex_byte
from conformance.targetinfo import TargetInfo
from conformance.verdict import CouldNotTest
from gve_fixtures.profile import Profile
from gve_fixtures.protocol import SECOND, ErrorCode, St6
from gve_fixtures.transcript import HOST, UNIT, Record


class Reachable(Protocol):
    """What a session needs of its target (conformance.targets.base.Target)."""

    info: TargetInfo
    profile: Profile
    address: int

    def connect(self, address: int | None) -> tuple[Any, int, bool, Any]: ...

#: the `*E` that closes a packet left open: -1 is no count of members, so it is refused
PACKET_CLOSER = "*E-1"
#: the `*E` that closes it on a unit that refused the first as a malformed frame and kept
#: the packet open: a count every reading takes, and one no member is committed by (none
#: taken: nothing to commit; some: their count differs)
SURE_CLOSER = "*E0"
#: status words restored at the end, polarity before causes before enables (an enable
#: written last finds its polarity and cause already in place)
RESTORE_ORDER = (2, 3, 4, 5, 0, 1)
#: during the way back, a frame at least every this many of the unit's restart times
#: (spec 2: about 2 s), so that a restart on the way is heard
WATCH = 0.25
#: EEPROM bytes read back in one go (one exchange with a co-simulator that takes frames
#: told ahead, docs/cosim.md: `batch`; a frame at a time on any other unit)
EEPROM_READS = 64


#: how often the known state asks whether a halted remainder `D` did not delete has run
#: out: a remainder whose axes did not move for that long is stuck (then `H` again)
RUN_OUT_POLL_S = 1.0
#: ST6 bits that keep a unit from being at rest for a case: moving, braking, or
#: interrupted with vectors waiting for `G` (spec 10.3: INTA/RUN 0/0 is idle [M])
NOT_AT_REST = St6.RUN | St6.STOP | St6.INTA
#: the codes a frame refused only while something runs may get: 7 ("za chodu vektoru
#: nelze") and 1 (`L` while anything is queued or running): "not yet", never a refusal
NOT_YET = (ErrorCode.BUSY, ErrorCode.QUEUE_FULL)
#: how often a frame answered "not yet" is sent again, each time once SR6 shows RUN = 0
NOT_YET_TRIES = 3


class SessionError(Exception):
    """The session cannot begin on this target (one line for the user)."""


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


@dataclass
class SessionReport:
    """What the session found, did and could not do: for the console and the reports."""

    target: str
    profile: str
    axes: list[str]
    real: bool
    identity: dict[str, str] = field(default_factory=dict)
    max_travel: int | None = None                   # full steps either side; None: emulator
    excursion: list[list[float]] | None = None      # per axis [min, max] in full steps
    found: dict[str, str] = field(default_factory=dict)
    restored: list[str] = field(default_factory=list)
    reset: list[str] = field(default_factory=list)   # could not be read: set to reset state
    problems: list[str] = field(default_factory=list)
    interrupted: bool = False
    not_responding: str = ""
    violations: list[str] = field(default_factory=list)   # answers outside the cases
    #: the line's round trip measured at the start (`?` exchanges): ms min, median, max,
    #: and the byte time at the baud rate
    line: dict[str, float] = field(default_factory=dict)
    #: where the session's time went: seconds per head of conformance/link/account.py
    #: and the wall time
    time: dict[str, float] = field(default_factory=dict)
    wire_log: list[str] = field(default_factory=list)

    def to_dict(self) -> dict:
        return asdict(self)


class Session:
    """What every target's session does: the guard's interface, links, Ctrl-C and the
    report. The embedded emulator's needs nothing more (:class:`EmuSession`); a real
    unit's adds the unit as found, the known state and the restorations
    (:class:`RealSession`)."""

    #: whether the unit outlives a link (and so is guarded, set and restored)
    real = False

    def __init__(self, target: Reachable, interrupts: Interrupts | None = None) -> None:
        self.target = target
        self.profile = target.profile
        info = target.info
        self.guard = self._guard(info, interrupts or Interrupts())
        self.report = SessionReport(info.spec, self.profile.name, list(self.profile.axes),
                                    self.real, max_travel=info.max_travel if self.real else None)
        self.started = False
        self.failed = ""                           # why the session could not begin
        self.finished = False
        self._link: Link | None = None             # the latest link (its checksum belief)
        #: the known-state steps that failed, each rule once (:class:`StepFailure`)
        self.failures: list[StepFailure] = []
        self._untaken = 0                           # failures not yet taken by the run
        self._before: Link | None = None            # the link before the known state's
        self.account = TimeAccount()                # where the session's time goes

    def _guard(self, info: TargetInfo, interrupts: Interrupts) -> Guard:
        return EmulatorGuard(self.profile, self.target.address, interrupts)

    @property
    def interrupts(self) -> Interrupts:
        """The run's Ctrl-C, held by the guard (which stops every frame after it)."""
        return self.guard.interrupts

    def share(self, interrupts: Interrupts) -> None:
        """Take Ctrl-C from the run's ``interrupts``."""
        self.guard.interrupts = interrupts

    # -- the guard's interface, for frames sent by other means ---------------------------------
    @property
    def before_motion(self) -> Callable[[], bool | None] | None:
        """Called once before the run's first frame that can move an axis; returning
        False refuses every motion frame of the run (SafetyStop)."""
        return self.guard.before_motion

    @before_motion.setter
    def before_motion(self, ask: Callable[[], bool | None] | None) -> None:
        self.guard.before_motion = ask

    def check(self, body: str, address: int | None = None) -> None:
        """Raise SafetyStop (or Interrupted, TargetNotResponding) if ``body`` may not go."""
        self.guard.check(body, address)

    def check_raw(self, data: bytes) -> None:
        """:meth:`check` every frame ``data`` holds, framed as a unit would."""
        self.guard.check_frames(HostFramer().frames(data), None)

    def accepted(self, body: str, response: Response | None, address: int | None = None) -> None:
        """Book ``body`` with its answer (None: none seen)."""
        self.guard.accepted(body, response, address)

    # -- links ----------------------------------------------------------------------------------
    def _new_link(self, address: int | None = None) -> Link:
        port, baud, virtual, rig = self.target.connect(address)
        link = Link(port, self.guard, address=self.target.address if address is None else address,
                    baud=baud, virtual=virtual, rig=rig)
        link.keep_account(self.account)
        self._link = link
        return link

    def open_link(self, address: int | None = None, tell: Sequence[str] = (),
                  meanwhile: Callable[[], None] | None = None) -> Link:
        """A link in the known state (on the emulator: a new unit, at ``address``).
        ``tell``: the frames the caller sends first on it, told ahead with the known
        state's last (Link.tell) where the unit lives on; ``meanwhile``: work of the
        caller's, done while the unit runs frames of the known state told ahead (else
        once the link is open)."""
        self.start()
        self.guard.check_idle()
        link = self._new_link(address)
        if meanwhile is not None:
            meanwhile()
        return link

    def start(self) -> None:
        """Read the unit as found, before the first case (real units only)."""
        if self.failed:
            raise SessionError(self.failed)
        if self.started:
            return
        self.started = True
        self.account.begin()
        self._as_found()

    def _as_found(self) -> None:
        """Nothing to read of a fresh unit."""

    def eeprom_as_found(self) -> dict[int, int]:
        """The EEPROM bytes as the run found them (read now if they were not: reading
        changes nothing); empty where the unit has no `ER` or every link is a new unit."""
        return self.guard.eeprom.originals

    def take_failures(self) -> list[StepFailure]:
        """The known-state steps that failed since the last call (each rule once a run),
        for the run to report as FAILs of their rules."""
        new = self.failures[self._untaken:]
        self._untaken = len(self.failures)
        return new

    def _step_failed(self, link: Link, failure: StepFailure) -> None:
        """Book ``failure`` (a rule already failed this run keeps its first evidence), its
        evidence read on ``link``: not where an answer on it did not belong to its frame
        (answered twice, or late), since then no answer read there is surely its frame's
        (that FAILs the case whatever the tag)."""
        if not link.violations and all(f.rule != failure.rule for f in self.failures):
            before = [] if self._before is None else \
                [rec.line() for rec in self._before.log[-LED_THERE_LINES:]]
            led = [*before, "# the known state", *link.transcript_lines()] if before \
                else link.transcript_lines()
            self.failures.append(replace(failure, led_there=tuple(led)))

    def after_case(self) -> None:
        """What a case changed that outlives it, put back (nothing on a fresh unit)."""

    def emergency_stop(self) -> None:
        """Ctrl-C: on a real unit `H`, then `D`, before anything else."""
        self.interrupts.handle()

    def finish(self) -> SessionReport:
        """Put back what the run changed and say what could not be (once)."""
        if self.finished:
            return self.report
        self.finished = True
        self._put_back()
        self.report.interrupted = self.report.interrupted or self.interrupts.stopped
        self.account.end()
        self.report.time = self.account.totals()
        return self.report

    def _put_back(self) -> None:
        """Nothing outlives a fresh unit."""


class EmuSession(Session):
    """The embedded emulator's session: every link a fresh unit."""


class RealSession(Session):
    """A real unit's session (see the module's docstring)."""

    real = True

    def __init__(self, target: Reachable, interrupts: Interrupts | None = None) -> None:
        super().__init__(target, interrupts)
        self.identity: dict[str, str] = {}
        self.status: dict[int, int] = {}           # ST0..ST5 as found
        self.checksums: bool | None = None         # the checksum mode as found
        self.counters: dict[int, int] = {}         # position counters as found (PF)
        #: where a test rig with eyes saw the axes as found (docs/rig.md, `physical`)
        self._rig_origin: dict[int, int] | None = None
        self._power_on_refused = ""                # why the rig did not power the unit on
        self.since_power_on = 0                     # ns: the restart waited out (open_powered)

    def _guard(self, info: TargetInfo, interrupts: Interrupts) -> Guard:
        return Guard(self.profile, self.target.address, max_travel=info.max_travel,
                     allow_destructive=info.allow_destructive, interrupts=interrupts)

    @property
    def eeprom(self) -> dict[int, int]:
        """The EEPROM bytes as found (the guard's ledger holds them)."""
        return self.guard.eeprom.originals

    def _new_link(self, address: int | None = None) -> Link:
        before = self._link
        link = super()._new_link(address)
        if before is not None:      # the same unit: its view from the wire too (its mode)
            link.view = before.view
        link.round_trip = self.report.line
        return link

    def open_link(self, address: int | None = None, tell: Sequence[str] = (),
                  meanwhile: Callable[[], None] | None = None) -> Link:
        before = self._link
        link = super().open_link(address)
        self._before = before
        link.meanwhile = meanwhile         # done at the known state's first frames told
        with self.guard.own_frames():
            try:
                self._known_state(link, tell)
            except StepFailed:
                # answers that did not belong to their frames (answered twice) misled
                # what the known state read: the case gets the link and FAILs on them
                if not link.violations:
                    raise
            finally:
                self._before = None
        link.log.clear()
        work, link.meanwhile = link.meanwhile, None
        if work is not None:
            work()
        return link

    @property
    def powers_on(self) -> bool:
        """Whether a link may begin at a power-on through the rig instead of the known
        state (:meth:`open_powered`): only a co-simulator in virtual time (its first line
        was `cosim 1`), which moves nothing physical, with a rig that has not refused
        `power-on`."""
        info = self.target.info
        return info.real and info.virtual_time and self._power_on_refused == "" \
            and getattr(self.target, "rig", None) is not None

    def open_powered(self) -> Link | None:
        """A link to the unit just powered on through its rig, in place of the known state:
        the rig's hands off, the power cycled (the guard books it as a restart: counters
        zeroed, the axes where they stand), the restart waited out on the suite's clock
        (no wall time), the checksum mode off as the manuals state the reset state
        (spec 9 [M]). The axes are then taken as standing where the run began: the guard's
        envelope re-centred there, since a co-simulator's axes are numbers, not a machine
        (docs/decisions.md). None where the rig refused `power-on` (the known state
        then, from here on)."""
        self.start()
        self.guard.check_idle()
        link = self._new_link()
        rig = link.rig
        try:
            rig.hands_off()
            rig.power_on()
        except CouldNotTest as err:
            self._power_on_refused = str(err)
            return None
        link.checksums = False
        powered = link.now
        link.wait(self.profile.restart_ms / 1000 + MARGIN, Spent.MANUAL)
        self.since_power_on = link.now - powered
        self.guard.recentre()
        link.log.clear()
        return link

    # -- the unit as found ----------------------------------------------------------------------
    def _as_found(self) -> None:
        with self._own_link() as link:
            self._read_as_found(link)

    def _read_as_found(self, link: Link) -> None:
        """Identity, checksum mode, status words, where the axes are, EEPROM."""
        self._probe_checksums(link)
        for name, body in (("version", "?"), ("processor_id", "Q")):
            r = link.send(body)
            if r is not None and r.ok:
                self.identity[name] = ",".join(r.values)
        self.report.identity = self.identity
        self.report.line = _round_trip(link)
        for n in range(6):
            r = link.send(f"SR{n}")
            if _hex_ok(r):
                self.status[n] = r.hex()
        self.report.found = {f"ST{n}": "%02X" % v for n, v in self.status.items()}
        self.report.found["checksums"] = "on" if self.checksums else "off"
        r = link.send("SR6")
        if _hex_ok(r) and _bits(r) & (St6.RUN | St6.STOP) and not _bits(r) & St6.INTA:
            # a unit may hold RUN a while after its last vector (a T dwell): not moving
            r = self._await_idle(link, self.profile.range("T").hi / 1000 + 2 * MARGIN) or r
        if _hex_ok(r):
            st6 = r.hex()
            self.report.found["ST6"] = "%02X" % st6
            if st6 & St6.STOP or (st6 & St6.RUN and not st6 & St6.INTA):
                self.failed = (f"{self.target.info.spec}: the unit reports RUN or STOP "
                               f"(ST6 = {st6:02X}): it is moving, or in hand-wheel (MPG) "
                               "mode; stop it before running the suite")
                self.report.problems.append(self.failed)
                raise SessionError(self.failed)
        self.counters = self._position(link)
        self.guard.envelope.origin(self.counters)
        self._rig_origin = self._rig_physical(link)
        if self.target.info.allow_destructive and "ER" in self.profile.commands:
            self._backup_eeprom(link)

    @contextlib.contextmanager
    def _own_link(self) -> Iterator[Link]:
        """A link for the session's own frames, its log kept for the report."""
        link = self._new_link()
        try:
            with self.guard.own_frames():
                yield link
        finally:
            self._keep_log(link)

    def _keep_log(self, link: Link) -> None:
        """The session's own frames and what went wrong there, for the report."""
        self.report.wire_log += link.transcript_lines()
        self.report.violations += [str(v) for v in link.violations]

    def _probe_checksums(self, link: Link) -> None:
        """The checksum mode as found: `?` without a checksum is refused (4) in the mode."""
        r = link.send("?", checksum=False)
        if r is not None and r.code == ErrorCode.SYNTAX:
            summed = link.send("?", checksum=True)
            if summed is not None and summed.ok:
                link.checksums = True
        self.checksums = link.checksums

    def _position(self, link: Link) -> dict[int, int]:
        r = link.send("PF")
        if r is None or not r.ok or len(r.values) < 3:
            return {}
        try:
            return {i: r.dec(i) for i in range(min(3, len(self.profile.axes)))}
        except AssertionError:
            return {}

    def eeprom_as_found(self) -> dict[int, int]:
        if not self.eeprom and "ER" in self.profile.commands:
            with self._own_link() as link:
                self._backup_eeprom(link)
        return self.eeprom

    def _backup_eeprom(self, link: Link) -> None:
        """Every byte the run can write, before its first EEPROM write: all of them."""
        read = _read_eeprom(link, list(range(self.profile.eeprom.size)))
        found = {address: r.hex() for address, r in read.items() if _hex_ok(r)}
        self.guard.eeprom.found(found)
        missing = self.profile.eeprom.size - len(found)
        if missing:
            self.report.problems.append(f"EEPROM: {missing} bytes could not be read, so "
                                        "they are not written")

    # -- the known state --------------------------------------------------------------------------
    def _halt(self, link: Link, timeout: float | None = None, *,
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

    def _reset_frames(self) -> list[str]:
        """What cannot be read, set to the reset state (spec 9)."""
        p, r = self.profile, self.profile.reset
        table = {"O0": "O0,%02X" % r.outputs, "XM": f"XM{r.XM}", "VN": "VK" if r.VK else "VN",
                 "VL": "VL" + ",".join(str(v) for v in known_axis_limits(p))}
        frames = [body for name, body in table.items() if name in p.commands]
        frames += [f"V{r.V}", f"A{r.A}", f"B{r.B}", f"${r.dollar}", f"T{r.T}"]
        if self._has_mpg():
            frames.append(f"Y{p.mpg.reset_mode}")
        if p.microstep:
            frames += [f"M{p.microstep.reset_mode}", f"M{p.microstep.reset_current}"]
        return frames

    def _has_mpg(self) -> bool:
        return self.profile.mpg is not None and "Y" in self.profile.commands

    def _stop(self, link: Link, then: Sequence[str] = ()) -> tuple[str, list[Response | None]]:
        """`H`, checksums off, the hand wheel (MPG) off, interrupts off (ST0..ST5 = 00), the
        save of a `K` the last case left given back with `R` (the manual's inverse of `K`:
        the queue back to its size), then `D`: the queue empty and ST6 clear (an input
        still enabled would set INTA again at once), read back with `SR6`; then the frames
        ``then``. Only the manuals' rules: no second `K`, no `R` with nothing kept. An MPG
        that EEPROM 06 made effective holds the axes (the unit is moving): `D` and EEPROM
        writes would be refused and the INTA of `H` outlive the stop, so it is off until
        the reset frames set its reset mode again. Returns why the unit is not at rest
        ("" when it is: :meth:`_at_rest`) and the answers to ``then``."""
        mpg = ["Y-"] if self._has_mpg() else []
        held = self.guard.keep_held and not self.interrupts.stopped
        # R moves nothing on a unit that keeps the manual (the save holds INTA with any
        # queue), but a unit that does not may run it: R only where the envelope takes it.
        # The halted vectors H left are deleted first: a unit may refuse R while they hold
        # RUN ("nelze použít za chodu" read as RUN = 1); what R gives back is deleted after
        give_back = ["D", "R"] if held and self.guard.fits("R") else []
        frames = [*mpg, *(f"SW{n},00" for n in range(6)), *give_back, "D", "SR6"]
        if not link.checksums and not self.guard.packet_open:
            link.tell(["H", *frames, *then])       # H as _halt sends it, then the rest
        halt = self._halt(link)
        if link.checksums:
            link.send("%-", checksum=True)
        answers = link.send_each(frames)
        if halt is not None and halt.code is not None and not halt.ok:
            self._step_failed(link, self._halt_refused(halt, link.checksums))
        why = self._at_rest(link, halt, answers[-2], answers[-1])
        if held and not give_back and not why:
            why = self._keep_not_given_back(link)
        if give_back and not why and not _taken(answers[-3]):
            why = self._give_back(link, answers[-3])
        return why, link.send_each(then)

    def _give_back(self, link: Link, restored: Response | None) -> str:
        """`R` was not taken after `D` left the unit at rest: "not yet" (7, 1) is asked
        again once `SR6` shows RUN = 0, and what it gives back deleted; refused at rest
        (read back before and after) it is a FAIL of `R`'s rule. Returns why the unit is
        not at rest ("" when it is)."""
        if _not_yet(restored):
            restored = self._when_idle(link, "R", restored)
            deleted, st6 = link.send_each(["D", "SR6"])
            if not _rests(st6):
                return ("the unit is not at rest after the known state gave back a KEEP: R "
                        f"{_shown(restored)}, D {_shown(deleted)}, SR6 reads {_shown(st6)}"
                        + _left(st6))
        if not _taken(restored):
            self._step_failed(link, StepFailure(
                "10.5.restore.exact", "restore", "R gives back the save of the K the unit "
                "accepted (not while moving)", f"R {_shown(restored)} at rest", "R accepted"))
        return ""

    def _await_idle(self, link: Link, seconds: float | None = None) -> Response | None:
        """`SR6` until it shows RUN and STOP clear (spec 10.3 [M]: RUN = 0 is nothing
        running), at most ``seconds`` (:meth:`_idle_seconds` unless given): that answer,
        else None (RUN stayed set, or `SR6` was not answered). Halted vectors (RUN with
        INTA) do not end by waiting: None at once."""
        def done(r: Response) -> bool:
            return not _hex_ok(r) or not _bits(r) & (St6.RUN | St6.STOP) \
                or bool(_bits(r) & St6.INTA)
        st6 = link.poll("SR6", done, self._idle_seconds() if seconds is None else seconds)
        idle = st6 is not None and _hex_ok(st6) and not _bits(st6) & (St6.RUN | St6.STOP)
        return st6 if idle else None

    def _idle_seconds(self) -> float:
        """The longest a unit may hold RUN once what it was asked is done: the longest
        T dwell a reader may give a vector with no motion (`L0,0,0`), or the longest stop
        the envelope allows, and the line's margin."""
        return (self.profile.range("T").hi / 1000 + 2 * self.guard.stop_seconds()
                + 2 * MARGIN)

    def _when_idle(self, link: Link, body: str, first: Response | None = None
                   ) -> Response | None:
        """``body`` (`N`, `N<axis>`, `M`, `R`, `EW`, the return `L`: refused while a
        vector runs) until it is answered otherwise than "not yet" (7, 1), each time
        again once `SR6` shows RUN = 0 (:meth:`_await_idle`): a unit may hold RUN for a
        T dwell after the `L0,0,0` the known state waits with, or read the manuals'
        "za chodu" as RUN = 1. ``first``: its answer already had (else it is sent now).
        The last answer."""
        r = link.send(body) if first is None else first
        for _ in range(NOT_YET_TRIES):
            if not _not_yet(r):
                return r
            if self._await_idle(link) is None:
                return r                # RUN stayed set, or vectors halted: not again
            r = link.send(body)
        return r

    def _halt_refused(self, halt: Response, summed: bool) -> StepFailure:
        """`H` answered otherwise than 8. `H` has no parameter: where the unit took `%+`
        (``summed``: the link believes the mode on) and refused `H` with 4, the code of a
        bad or missing checksum, in both framings (:meth:`_halt` tries each), it refuses
        frames summed as the manual sums them (a FAIL of that rule); any other answer is a
        FAIL of `H`'s own."""
        if halt.code == ErrorCode.SYNTAX and summed:
            return StepFailure(
                "6.checksum.sum", "halt", "H framed as the manual states, summed from ! up "
                "to and including the comma in checksum mode and plain otherwise, is taken",
                f"H {_shown(halt)} in either framing", "8")
        return StepFailure("10.cmd.halt-answer", "halt", "H is answered 8",
                           f"H {_shown(halt)}", "8")

    def _at_rest(self, link: Link, halt: Response | None, deleted: Response | None,
                 st6: Response | None) -> str:
        """Whether the stop left the unit at rest: RUN, STOP and INTA clear in ST6, as `D`
        after `H` leaves it (spec 10.4 [M]: `D` is for the rest of the queue after an
        interruption, and clears ST6). Where an INTA that `H` set outlives `D`, `D` did
        not do what its rule says (a FAIL of that rule); the unit is then brought to rest by
        other means (:meth:`_to_rest`) and ST6 is read again. Returns why the unit is not
        at rest ("" when it is)."""
        if _rests(st6):
            return ""
        if not _bits(st6) & St6.INTA and halt is not None:
            # moving or braking with no stop of H's left: given the longest stop to end
            st6 = link.poll("SR6", _rests, 2 * self.guard.stop_seconds() + 2) or st6
            if _rests(st6):
                return ""
        if halt is not None and halt.ok and _hex_ok(st6) and _bits(st6) & St6.INTA:
            # what the bookkeeping took for deleted may still be queued: no position read
            # tells where the axes rest until the unit shows rest
            self.guard.doubt_rest()
            self._step_failed(link, self._not_deleted(link, halt, deleted, st6))
            if not self.interrupts.stopped:
                st6 = self._to_rest(link)
                if _rests(st6):
                    return ""
        if st6 is not None and not st6.ok:
            return ("the unit refuses the known state's frames, its status unread: H "
                    f"{_shown(halt)}, SR6 {_shown(st6)}")
        return f"the unit is not at rest after the known state: SR6 reads {_shown(st6)}" \
            + _left(st6)

    def _not_deleted(self, link: Link, halt: Response, deleted: Response | None,
                     st6: Response) -> StepFailure:
        """`D` after `H` left INTA. Refused as busy (7: "not while moving"), `PF` read
        twice tells whether the axes still move: moving after `H` was answered, the frame
        that answers only once they stopped (spec 2) did not — the `W` that last set them
        moving where one did (spec 10: under simplex `H` cannot meet a `W` run that
        answered when done; whether `H` stops one is the manuals' silence), else `H`.
        At rest, `D` broke its own rule."""
        evidence = f"H {_shown(halt)}, D {_shown(deleted)}, SR6 {_shown(st6)}"
        if deleted is not None and deleted.code is not None \
                and deleted.code & 7 == ErrorCode.BUSY:
            first = self._position(link)
            link.wait(RUN_OUT_POLL_S, Spent.MOTION)
            then = self._position(link)
            evidence += f", PF {_counters(first)} then {_counters(then)}"
            last = ("", False) if self._before is None else _last_motion(self._before.log)
            # a W whose answer never came: whether H stops its run is the manuals' silence
            if first and then and first != then and last != ("W", False):
                if last == ("W", True):
                    return StepFailure(
                        "10.cmd.reference", "reference", "W answers only when its run is "
                        "over: the axes still moved after its answer (and H's)", evidence,
                        "the axes at rest from W's answer on")
                return StepFailure("10.4.halt.ramp", "halt", "H answers only when the unit "
                                   "has stopped", evidence, "the axes at rest from H's answer on")
        return StepFailure(
            "10.4.delete", "delete", "D after H (the unit stopped) empties the queue and "
            "clears ST6", evidence, "D 0, then SR6 with RUN, STOP and INTA clear")

    def _keep_not_given_back(self, link: Link) -> str:
        """A `K` the last case left whose save `R` would give back beyond the envelope:
        `J` where destructive commands are allowed (the save gone with the reset); else
        why the unit is not in the known state (its queue takes one `L` only)."""
        if self._may_reset():
            return "" if _rests(self._reset(link)) else "the unit is not at rest after J"
        return ("a KEEP the last case left is still held (its R would give back a queue "
                "the envelope cannot take), and J, which would clear it, needs "
                "--allow-destructive")

    def _may_reset(self) -> bool:
        return self.guard.allow_destructive and "J" in self.profile.commands

    def _reset(self, link: Link) -> Response | None:
        """`J` (the reset state: ST6 = 00, spec 9 [M]), the hand wheel off and what cannot
        be read set again; the position read at rest before and after (J zeroes the
        counters: only a read before tells where the axes stand), ST6 read back."""
        self._position(link)
        link.send("J")
        link.wait(self.profile.restart_ms / 1000 + MARGIN, Spent.MANUAL)
        link.send_each([*(["Y-"] if self._has_mpg() else []), *self._reset_frames()])
        self._position(link)
        return link.send("SR6")

    def _to_rest(self, link: Link) -> Response | None:
        """At rest by other means than `D`, by the manuals' rules: `G`, and the remainder
        runs out (:meth:`_run_out`; the axes end where the bookkeeping knows them); still
        not at rest, `J` where destructive commands are allowed (the reset state, ST6 = 00:
        spec 9 [M]) and what cannot be read set again. Then the position read at rest,
        and ST6 again."""
        if not self._run_out(link):
            self._halt(link)
        self._position(link)
        st6 = self._await_idle(link) or link.send("SR6")
        return st6 if _rests(st6) or not self._may_reset() else self._reset(link)

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

    def _settle(self, link: Link, then: Sequence[str] = ()
                ) -> tuple[str, dict[str, Response | None]]:
        """The rig's hands off (a simulator's rig: inputs and switches as found), stopped
        (:meth:`_stop`), the reset values of what cannot be read, then the frames
        ``then``. Returns why the unit is not at rest ("" when it is) and the answers to
        the frames after the stop, by frame."""
        if link.rig is not None:
            link.rig.hands_off()
        after = [*self._reset_frames(), *then]
        why, answers = self._stop(link, after)
        return why, dict(zip(after, answers, strict=True))

    def _known_state(self, link: Link, tell: Sequence[str] = ()) -> None:
        """Stopped and at rest (read back), the reset values, the axes back where the run
        began, the counters zeroed (read back); :class:`StepFailed` when the unit could
        not be brought there. The hand wheel's reset mode `&` switches the MPG on (M114
        13.6.8), which holds the axes (RUN without INTA) wherever the unit's active
        configuration enables it — also after a case's EEPROM 06 was put back, on a unit
        that reads its EEPROM at reset only: then it is turned off again (`Y-`)."""
        left, _ = self._settle(link, ["PF"])       # where the axes are, for the way back
        if left:
            raise StepFailed(left)
        if self._has_mpg():
            st6 = link.send("SR6")
            if st6 is not None and st6.ok and st6.values and is_hex_byte(st6.values[0]) \
                    and int(st6.values[0], 16) & (St6.RUN | St6.INTA) == St6.RUN:
                link.send("Y-")
        spindle = self.profile.spindle
        if spindle is not None:
            # the spindle off, as after reset (M114 13.5 "O0,FF - Výstup vypnutý"): `O0`
            # need not reset the setting of `!7V`, which a case or sequence may have left
            link.send("V0", address=spindle.address)
        returned, there = self._go_back(link, read=False)
        link.tell(["N", "PF", *tell])
        self._zero(link, returned, there)

    def _zero(self, link: Link, returned: str = "", there: dict[int, int] | None = None
              ) -> None:
        """`N`, read back with `PF`: every counter 0 (spec 10 [M]); answered "not yet"
        (7: a unit may hold RUN a T dwell after the `L0,0,0` that ended the return move)
        it is sent again once `SR6` shows RUN = 0. Where `N` did not zero them at rest, a
        FAIL of its rule, and `N<axis>0` where the unit has it; counters still elsewhere
        leave the case COULD-NOT-TEST (cases judge positions from 0). ``returned``: the
        return move just ended by `L0,0,0`, ``there``: `PF` right after it (axes that
        moved on from there broke the wait idiom: :meth:`_returning`)."""
        zeroed = link.send("N")
        if returned and _not_yet(zeroed):
            st6 = link.send("SR6")
            if not _rests(st6):
                self._returning(link, returned, there, zeroed, st6)
        zeroed = self._when_idle(link, "N", zeroed)
        with self.guard.unmoved():                 # at rest: a counter read is no motion
            here = self._position(link)
        if _taken(zeroed) and here and not any(here.values()):
            return                                 # taken: nothing runs (7 if RUN = 1)
        st6 = link.send("SR6")
        if not _rests(st6):
            raise StepFailed(f"the unit is not at rest after the known state: N answered "
                             f"{_shown(zeroed)}, SR6 reads {_shown(st6)}" + _left(st6))
        self._step_failed(link, StepFailure(
            "10.cmd.zero", "zero", "N zeroes every axis counter (the unit at rest)",
            f"N {_shown(zeroed)}, PF {_counters(here)}", "N 0, PF 0 on every axis"))
        names = self.profile.axes
        setters = [f"N{a}0" for a in names[:3] if f"N{a}" in self.profile.commands]
        if setters:
            for body in setters:
                self._when_idle(link, body)
            with self.guard.unmoved():
                here = self._position(link)
            if here and not any(here.values()):
                return
        raise StepFailed(f"the position counters could not be zeroed (N answered "
                         f"{_shown(zeroed)}, PF then {_counters(here)}): the cases judge "
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
        if not _hex_ok(st6) or not _bits(st6) & St6.RUN:
            return False
        rested = link.poll("SR6", _rests, self._return_seconds(body)) is not None
        if rested and there:
            with self.guard.unmoved():              # at rest: a counter read is no motion
                then = self._position(link)
            if then and then != there:
                self._step_failed(link, StepFailure(
                    "10.1.queue.wait-idiom", "return-move", "L0,0,0 after the return move "
                    "answers 1 until the move has finished, then 0: the axes no longer "
                    "move once it is answered 0",
                    f"{body} 0, L0,0,0 0, PF {_counters(there)}, then N {_shown(zeroed)}, "
                    f"SR6 {_shown(st6)}, and at rest PF {_counters(then)}",
                    "the axes where PF read them once L0,0,0 was answered 0"))
        return rested

    def _return_seconds(self, body: str) -> float:
        """The longest the return move ``body`` (an `L` at the reset V) may take."""
        cruise = max(abs(int(v)) for v in body[1:].split(",")) / self.profile.reset.V
        return cruise * 2 + 2 * self.guard.stop_seconds() + 2

    def _go_back(self, link: Link, *, read: bool = True) -> tuple[str, dict[int, int]]:
        """Move the axes back to where the run began (known exactly only at rest; the
        counters read first unless ``read`` is False: just read). After a restart that
        left them anywhere on their trail, a test rig's eyes locate them first, when the
        rig has eyes. Returns the frame that moved them ("" none) and the counters read
        at the end."""
        read_now = self._position(link) if read else {}
        envelope = self.guard.envelope
        if None in envelope.position():
            self._relocate(link)
        if envelope.unheld:
            axes = ", ".join(sorted({self.profile.axes[i] for i in envelope.unheld}))
            why = (f"position counters ({axes}) set with N<axis> read back other values at "
                   "rest: taken for counters that do not hold them, the axes where the "
                   "frames put them")
            if why not in self.report.problems:
                self.report.problems.append(why)
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
            if why not in self.report.problems:
                self.report.problems.append(why)
            return "", read_now
        r = self._when_idle(link, body)
        if r is None or not r.ok:
            self._return_refused(link, body, r)
            return "", self._position(link)
        cruise = max(abs(b) for b in back) / speed        # the least the way back takes
        seconds = self._return_seconds(body)
        # watched as long as it takes with its ramps at the reset acceleration (A in
        # 1000 steps/s²), so that the first L0,0,0 after it is taken (one poll, not two)
        self._watch(link, cruise + speed / (self.profile.reset.A * 1000))
        if link.poll("L0,0,0", lambda r: r.ok, seconds) is None:
            self._step_failed(link, StepFailure(
                "10.1.queue.wait-idiom", "return-move", "the return move, an L from rest, "
                f"ends: L0,0,0 is then taken (within {seconds:.1f} s)",
                f"{body} 0, L0,0,0 not taken", "L0,0,0 answered 0"))
            raise StepFailed("the return to where the run began did not end in time")
        return body, self._position(link)

    def _return_refused(self, link: Link, body: str, r: Response | None) -> None:
        """The return move answered otherwise than 0: at rest (ST6 read back) that is a
        FAIL of `L` from rest (spec 10.1 [M]) and the axes stay where they are (the
        envelope still bounds every frame); else the case cannot begin."""
        st6 = link.send("SR6") if r is not None else None
        if not _rests(st6):
            raise StepFailed(f"the return to where the run began ({body}) answered "
                             f"{_shown(r)}, SR6 then {_shown(st6)}" + _left(st6))
        self._step_failed(link, StepFailure(
            "10.1.queue.line-alone", "return-move", "the return move, an L with nothing "
            "queued or running (the unit read back at rest), is accepted",
            f"{body} {_shown(r)}, SR6 {_shown(st6)}", f"{body} 0"))

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

    def _relocate(self, link: Link) -> None:
        """Where the axes are when the frames no longer tell (a restart left them anywhere
        on their trail, a `W` at a switch the suite cannot see): a test rig's eyes (a
        simulator's `physical`, docs/rig.md) tell, when the rig has them; the guard then
        lets motion go out again."""
        if self._rig_origin is None:
            return
        now = self._rig_physical(link)
        counters = self._position(link)
        if now is None or len(counters) < min(3, len(self.profile.axes)):
            return
        self.guard.locate({a: now[a] - self._rig_origin[a] for a in now}, counters)

    def _rig_physical(self, link: Link) -> dict[int, int] | None:
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

    # -- Ctrl-C and the end --------------------------------------------------------------------
    def emergency_stop(self) -> None:
        if self._link is not None:
            self.report.interrupted = True
            wait = None if self.guard.responding else MARGIN
            try:
                with self.guard.emergency():
                    self._halt(self._link, timeout=wait, urgent=True)
                    self._link.send("D", timeout=wait)
            except TargetNotResponding as err:          # gone (its port, its program)
                self.report.problems.append(f"H and D after Ctrl-C not sent: {err}")
        self.interrupts.handle()

    def _put_back(self) -> None:
        if self.started and not self.failed:     # found moving: untouched
            if self.interrupts.pending:
                self.emergency_stop()
            link = self._new_link()
            try:
                with self.guard.own_frames():
                    self._restore(link)
            except Interrupted:
                self.emergency_stop()
                self.report.problems.append("restorations stopped by Ctrl-C: what follows "
                                            "was not put back")
                self._unrestored()
            except (TargetNotResponding, SafetyStop, CouldNotTest) as err:
                self.report.problems.append(f"restorations stopped: {err}")
                self._unrestored()
            self._keep_log(link)
        # what happened to the unit first: it explains what could not be put back
        self.report.problems[:0] = [str(r) for r in (*self.guard.restarts,
                                                     *self.guard.untracked)]
        self.report.excursion = [list(e) for e in self.guard.excursion()]

    def _restore(self, link: Link) -> None:
        if not self.guard.responding:
            self.report.not_responding = "the target stopped responding"
            with self.guard.emergency():              # once, without waiting long
                self._halt(link, timeout=MARGIN, urgent=True)
                link.send("D")
            raise TargetNotResponding("the target is not responding")
        left, answers = self._settle(link)
        if left:
            self.report.problems.append(f"the unit is not left at rest: {left}")
        self._say_reset(answers)
        self._restore_axes(link)
        self._restore_counters(link)
        self._restore_eeprom(link)
        self._restore_status(link)
        self._restore_checksums(link)

    def _say_reset(self, answers: dict[str, Response | None]) -> None:
        """What cannot be read back, set to the reset state: said of the frames the unit
        took (answered 0), a problem for the others."""
        frames = self._reset_frames()
        taken = [body for body in frames if _taken(answers.get(body))]
        # M114 12: "Pokud je hodnota některého parametru mimo rozsah, není možné MPG
        # použít": the MPG mode refused out of range where the EEPROM does not allow it
        # is that unit's reset state, nothing left to set
        inert = [body for body in frames if body.startswith("Y") and self._has_mpg()
                 and _refused_range(answers.get(body))]
        refused = [f"{body} answered {_shown(answers.get(body))}" for body in frames
                   if body not in taken and body not in inert]
        if taken:
            self.report.reset.append("set to the reset state, each answered 0 (they cannot "
                                     "be read back): " + ", ".join(taken))
        if inert:
            self.report.reset.append("the MPG mode left as the unit's EEPROM makes it (the "
                                     "MPG not allowed there): " + ", ".join(
                                         f"{b} answered {_shown(answers.get(b))}" for b in inert))
        if refused:
            self.report.problems.append("not set to the reset state: " + "; ".join(refused))
        micro = self.profile.microstep
        if micro and all(f"M{m}" in taken for m in (micro.reset_mode, micro.reset_current)):
            self.report.reset.append("GVE54 micro-step mode and current set to "
                                     f"M{micro.reset_mode}, M{micro.reset_current} (the reset "
                                     "state)")

    def _restore_axes(self, link: Link) -> None:
        """The axes back where the run began, as the counters then read; where they are
        not, a problem saying where they are. An axis no position read shows (the
        GVE114's A: PF reads X, Y, Z, M114 13.6.6) cannot be verified: said as such."""
        names = self.profile.axes
        stopped = self.interrupts.stopped
        if self.guard.recentred and not stopped:
            # a co-simulator in virtual time, its envelope re-centred at every power-on
            # start: nothing physical moved, so nothing is brought back (nor said restored)
            where = self._rig_physical(link)
            self.report.reset.append(
                "the co-simulator's axes left where its last sequence put them"
                + (f" ({_counters(where)} counter units from where it started, by its rig)"
                   if where else "")
                + ": its envelope was re-centred at every power-on start, nothing physical "
                  "moving in virtual time")
            return
        if not stopped and None in self.guard.envelope.position():
            self._relocate(link)
        body, read = "", {}
        if stopped or self.guard.lost:
            read = self._position(link)
        else:
            try:
                body, read = self._go_back(link)
            except CouldNotTest as err:
                self._axes_left(str(err))
                return
        here = self.guard.envelope.position()
        shown = min(3, len(names))
        away = [a for a, h in zip(names[:shown], here, strict=False) if h != 0]
        if away:
            unknown = [a for a, h in zip(names, here, strict=True) if h is None]
            self._axes_left("no motion after a signal" if stopped else
                            f"no motion after it: {self.guard.lost}" if self.guard.lost else
                            f"where {', '.join(unknown)} stand is not known exactly" if unknown
                            else "the way back would have left the envelope")
            return
        if self.guard.recentred and self._rig_origin is None:
            self._axes_left("the envelope was re-centred at each power-on of the "
                            "co-simulator, and its rig has no eyes to say where they are")
            return
        moved = (f"moved back with {body} at V{self.profile.reset.V}" if body else
                 "no motion after the signal" if stopped else "no move needed")
        which = "" if shown == len(names) else f" {', '.join(names[:shown])}"
        self.report.restored.append(f"axes{which} back where the run began ({moved}); PF then "
                                    f"read {_counters(read)}, where the frames put them")
        for i in range(shown, len(names)):
            if here[i] != 0:
                self.report.reset.append(
                    f"axis {names[i]} not verified: no position read shows it (PF reads "
                    f"{', '.join(names[:shown])}), and the frames leave it anywhere in "
                    f"{self.guard.where(i)} full steps from where the run began")
            else:
                self.report.reset.append(f"axis {names[i]} back where the run began by the "
                                         "frames (no position read shows it)")

    def _axes_left(self, why: str) -> None:
        self.report.problems.append(f"axes not brought back where the run began ({why}): "
                                    f"{self.guard.whereabouts()} full steps from there")

    def _restore_counters(self, link: Link) -> None:
        """The position counters count as they did before the run: as found where the
        axes are back where the run began, found plus how far they are from there where
        they are not (N<axis>), read back with PF."""
        names = self.profile.axes
        if not self.counters:
            self.report.problems.append("position counters not restored: PF could not be "
                                        "read before the run")
            return
        if self.guard.recentred and not any(self.counters.values()):
            # a co-simulator found with its power-on counters: powered on once more, as
            # every sequence began, they read as found (or the problem says what they read)
            link.rig.power_on()
            link.checksums = False
            link.wait(self.profile.restart_ms / 1000 + MARGIN, Spent.MANUAL)
            self.guard.recentre()
            read = self._position(link)
            if read == self.counters:
                self.report.restored.append(f"position counters as found: PF reads "
                                            f"{_counters(read)} (the co-simulator powered on "
                                            "as every sequence began)")
            else:
                self.report.problems.append(f"position counters not restored: after a "
                                            f"power-on PF read {_counters(read)}")
            return
        here = self.guard.envelope.position()
        unknown = [names[i] for i in self.counters if here[i] is None]
        if unknown:
            self.report.problems.append(
                f"position counters {', '.join(unknown)} not restored: where the axes "
                "stand is not known exactly, so the counts found cannot be carried to them")
        wanted = {i: c + int(here[i]) for i, c in self.counters.items() if here[i] is not None}
        settable = {i: v for i, v in wanted.items() if f"N{names[i]}" in self.profile.commands}
        sent = [f"N{names[i]}{v}" for i, v in settable.items()]
        for body in sent:
            self._when_idle(link, body)
        read = self._position(link)
        found = _counters(self.counters)
        if any(read.get(i) != v for i, v in settable.items()):
            self.report.problems.append(
                f"position counters not restored: {', '.join(sent)} sent, PF then read "
                f"{_counters(read)}")
        elif any(read.get(i) != v for i, v in wanted.items()):
            # no N<axis> (the GVE54): left as the run's N set them where it began
            self.report.reset.append(
                f"position counters left reading {_counters(read)} (found {found}; the "
                f"{self.profile.name} has no N<axis> to set them)")
        elif wanted == self.counters:
            self.report.restored.append(f"position counters as found: PF reads "
                                        f"{_counters(read)}"
                                        + (f" (set with {', '.join(sent)})" if sent else ""))
        elif wanted:
            self.report.restored.append(
                f"position counters count from where they did before the run (found {found}, "
                f"the axes now {self.guard.whereabouts()} full steps from there): "
                f"{', '.join(sent)}; PF reads {_counters(read)}")

    def after_case(self) -> None:
        """EEPROM bytes a case wrote are put back as soon as it ends, so that no later
        case meets them (e.g. 06 turning the GVE114's hand wheel on after a J); the end
        of the run verifies every byte again. The unit is stopped first: a case (or a
        diff sequence) may leave it moving, and a moving unit refuses EEPROM writes."""
        if not self.guard.eeprom.written or self.failed:
            return
        with self._own_link() as link:
            self._stop(link)
            self._eeprom_back(link, sorted(self.guard.eeprom.written))

    def _eeprom_back(self, link: Link, addresses: list[int]) -> list[str]:
        """Read ``addresses``, write back those that differ from the originals and read
        them again; returns those written back (a failure is a problem)."""
        changed = []
        read = _read_eeprom(link, addresses)
        for address in addresses:
            value = self.eeprom[address]
            r = read[address]
            if _hex_ok(r) and r.hex() == value:
                continue
            self._when_idle(link, "EW%02X,%02X" % (address, value))
            r = link.send("ER%02X" % address)
            if _hex_ok(r) and r.hex() == value:
                changed.append("%02X" % address)
            else:
                self.report.problems.append(f"EEPROM {address:02X} not restored to {value:02X}: "
                                            f"written back, ER{address:02X} then answered "
                                            f"{_shown(r)}")
        self.guard.eeprom.put_back(addresses)
        return changed

    def _restore_eeprom(self, link: Link) -> None:
        if not self.guard.eeprom.ever_written:
            return
        before = len(self.report.problems)
        changed = self._eeprom_back(link, sorted(self.eeprom))
        wrong = len(self.report.problems) - before
        self.report.restored.append(
            f"EEPROM: {len(self.eeprom) - wrong} of {len(self.eeprom)} bytes verified, read "
            "back as found" + (f" ({' '.join(changed)} written back first)" if changed else ""))

    def _restore_status(self, link: Link) -> None:
        for n in RESTORE_ORDER:
            if n in self.status:
                link.send("SW%d,%02X" % (n, self.status[n]))
        wrong = []
        for n, value in sorted(self.status.items()):
            r = link.send(f"SR{n}")
            if not (_hex_ok(r) and r.hex() == value):
                wrong.append(f"SR{n} answered {_shown(r)}, found {value:02X}")
        wrong += [f"ST{n} could not be read before the run, left 00" for n in range(6)
                  if n not in self.status]
        if wrong:
            self.report.problems.append("status words not restored: " + "; ".join(wrong))
        elif self.status:
            self.report.restored.append("ST0..ST5 written back and read back as found: "
                                        + " ".join("%02X" % v for _, v in
                                                   sorted(self.status.items())))

    def _restore_checksums(self, link: Link) -> None:
        """The checksum mode as found (the known state left it off), read back as it was
        found: `?` without a checksum is refused (4) in the mode (spec 6)."""
        if self.checksums:
            r = link.send("%+", checksum=False)
            if r is None or not r.ok:
                self.report.problems.append(f"checksum mode not turned back on: %+ answered "
                                            f"{_shown(r)}")
                return
        r = link.send("?", checksum=False)
        on = r is not None and r.code == ErrorCode.SYNTAX
        off = r is not None and r.ok
        if on if self.checksums else off:
            self.report.restored.append(
                "checksum mode " + ("back on: %+ answered, then ? without a checksum was "
                                    "refused (4)" if self.checksums else
                                    "off as found: ? without a checksum answered"))
        else:
            self.report.problems.append(
                f"checksum mode not {'on' if self.checksums else 'off'} as found: ? without "
                f"a checksum answered {_shown(r)}")

    def _unrestored(self) -> None:
        if not any(line.startswith("axes") for line in self.report.restored + self.report.problems):
            self._axes_left("the restorations stopped before")
        if self.guard.eeprom.written:
            written = sorted(self.guard.eeprom.written)
            self.report.problems.append("EEPROM not verified: bytes written by the run: "
                                        + " ".join("%02X" % a for a in written))
        if self.status:
            self.report.problems.append("status words not verified as found: " + " ".join(
                f"ST{n}={v:02X}" for n, v in sorted(self.status.items())))


#: `?` exchanges that measure the line's round trip at the start of a session
ROUND_TRIPS = 5


def _round_trip(link: Link) -> dict[str, float]:
    """The round trip of a harmless `?` in ms (min, median, max), one byte's time at the
    link's baud rate and the time of one exchange's bytes (frame and answer): what the
    line adds to every exchange (conformance/link/line_band.py)."""
    answers = [r for r in (link.send("?") for _ in range(ROUND_TRIPS)) if r is not None]
    trips = sorted((r.received_at - r.sent_at) / 1e6 for r in answers)
    if not trips:
        return {}
    sent = len(frame("?", link.address, link.checksums))
    return {"min_ms": trips[0], "median_ms": trips[len(trips) // 2], "max_ms": trips[-1],
            "byte_ms": link.byte_seconds(1) * 1e3,
            "bytes_ms": link.byte_seconds(sent + len(answers[0].raw)) * 1e3}


def _read_eeprom(link: Link, addresses: list[int]) -> dict[int, Response | None]:
    """`ER` of each address in turn, EEPROM_READS frames told ahead at a time."""
    read: dict[int, Response | None] = {}
    for start in range(0, len(addresses), EEPROM_READS):
        chunk = addresses[start:start + EEPROM_READS]
        read.update(zip(chunk, link.send_each(["ER%02X" % a for a in chunk]), strict=True))
    return read


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


def _shown(r: Response | None) -> str:
    """An answer as a report says it: its bytes escaped but its last CR, or that none
    came."""
    return "nothing" if r is None else readable(r.raw.removesuffix(b"\r"))


def _taken(r: Response | None) -> bool:
    return r is not None and r.ok


def _refused_range(r: Response | None) -> bool:
    return r is not None and r.code is not None and r.code & 7 == ErrorCode.RANGE


def _not_yet(r: Response | None) -> bool:
    """Whether ``r`` refuses its frame only while something runs (7, 1: not yet)."""
    return r is not None and r.code is not None and r.code & 7 in NOT_YET


def _counters(read: dict[int, int]) -> str:
    """Counters as PF shows them: ``394,0,0`` (``?`` for an axis not read)."""
    return ",".join(str(v) for v in read.values()) if read else "nothing readable"


def _bits(st6: Response | None) -> St6:
    """ST6 as an `SR6` answer gives it (every bit set when it gives none: not at rest)."""
    return St6(st6.hex()) if _hex_ok(st6) else St6(0xFF)


def _rests(st6: Response | None) -> bool:
    """Whether an `SR6` answer shows the unit at rest (RUN, STOP and INTA clear)."""
    return not _bits(st6) & NOT_AT_REST


def _left(st6: Response | None) -> str:
    """What an `SR6` answer shows left (" (RUN, INTA)"), or nothing."""
    if not _hex_ok(st6):
        return ""
    names = [b.name for b in (St6.RUN, St6.STOP, St6.INTA) if st6.hex() & b]
    return f" ({', '.join(n or '' for n in names)})" if names else ""


def _hex_ok(r: Response | None) -> bool:
    return r is not None and r.ok and len(r.values) >= 1 and is_hex_byte(r.values[0])


def open_session(target: Reachable, interrupts: Interrupts | None = None) -> Session:
    """The session ``target`` needs: a real unit's, or the embedded emulator's."""
    return (RealSession if target.info.real else EmuSession)(target, interrupts)
