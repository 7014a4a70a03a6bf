"""The run-wide session on one target: one per target per run.

It owns what must hold for the whole run on one unit, across links, cases and Hypothesis
examples:

- the :class:`~conformance.link.safety.Guard` every link of the run shares (the motion
  envelope in physical steps, the destructive guard, Ctrl-C, the count of unanswered
  frames), whose interface it offers (:meth:`Session.check`, :meth:`Session.check_raw`,
  :meth:`Session.accepted`) to whoever sends frames by other means;
- the unit as found (:meth:`start`, before the first case; :mod:`.as_found`): its
  identity (`?`, `Q`), its checksum mode, ST0..ST5, where the axes are, and — when
  destructive commands are allowed — every EEPROM byte, before the run's first EEPROM
  write;
- the known state a case starts from (:meth:`open_link`), which
  :class:`~conformance.known_state.procedure.KnownState` sets by the manuals' rules only
  and reads back; the steps of it that failed, once a run each (:meth:`take_failures`);
- Ctrl-C (:meth:`emergency_stop`: `H`, then `D`) and the restorations (:meth:`finish`,
  :class:`~conformance.targets.restorations.Restorations`): EEPROM and status words put
  back and verified by reading back, the checksum mode as found, what cannot be read set
  to the reset state; what could not be restored goes into :attr:`report` as a problem.

On the embedded emulator every link is a fresh unit: nothing to protect or restore; its
session (:class:`EmuSession`) still carries Ctrl-C and the count of unanswered frames. A
real unit's (:class:`RealSession`) does all of the above; :func:`open_session` picks one.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterator, Sequence
from typing import Any, Protocol

from conformance.known_state.answers import bits, hex_ok
from conformance.known_state.failed_steps import Failures, StepFailed, StepFailure
from conformance.known_state.procedure import KnownState
from conformance.link.account import Spent, TimeAccount
from conformance.link.framing import HostFramer, Response
from conformance.link.link import MARGIN, Link
from conformance.link.liveness import TargetNotResponding
from conformance.link.safety import EmulatorGuard, Guard
from conformance.link.signals import Interrupted, StopSignals
from conformance.link.stops import SafetyStop
from conformance.targets.as_found import AsFound, read_eeprom, round_trip
from conformance.targets.info import TargetInfo
from conformance.targets.restorations import Restorations
from conformance.targets.session_report import SessionReport
from conformance.verdicts.verdict import CouldNotTest
from gve_fixtures.profile import Profile
from gve_fixtures.protocol import ErrorCode, St6


class Reachable(Protocol):
    """What a session needs of its target (conformance.targets.target.Target)."""

    info: TargetInfo
    profile: Profile
    address: int

    def connect(self, address: int | None) -> tuple[Any, int, bool, Any]: ...


class SessionError(Exception):
    """The session cannot begin on this target (one line for the user)."""


class Session:
    """What every target's session does: the guard's interface, links, Ctrl-C and the
    report. The embedded emulator's needs nothing more (:class:`EmuSession`); a real
    unit's adds the unit as found, the known state and the restorations
    (:class:`RealSession`)."""

    #: whether the unit outlives a link (and so is guarded, set and restored)
    real = False

    def __init__(self, target: Reachable, interrupts: StopSignals | None = None) -> None:
        self.target = target
        self.profile = target.profile
        info = target.info
        self.guard = self._guard(info, interrupts or StopSignals())
        self.report = SessionReport(info.spec, self.profile.name, list(self.profile.axes),
                                    self.real, max_travel=info.max_travel if self.real else None)
        self.started = False
        self.failed = ""                           # why the session could not begin
        self.finished = False
        self._link: Link | None = None             # the latest link (its checksum belief)
        #: the known-state steps that failed, each rule once (:class:`StepFailure`)
        self.book = Failures()
        self.account = TimeAccount()                # where the session's time goes

    def _guard(self, info: TargetInfo, interrupts: StopSignals) -> Guard:
        return EmulatorGuard(self.profile, self.target.address, interrupts)

    @property
    def interrupts(self) -> StopSignals:
        """The run's Ctrl-C, held by the guard (which stops every frame after it)."""
        return self.guard.interrupts

    def share(self, interrupts: StopSignals) -> None:
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

    @property
    def failures(self) -> list[StepFailure]:
        """The known-state steps that failed in the run, each rule once."""
        return self.book.booked

    def take_failures(self) -> list[StepFailure]:
        """The known-state steps that failed since the last call (each rule once a run),
        for the run to report as FAILs of their rules."""
        return self.book.take()

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

    def __init__(self, target: Reachable, interrupts: StopSignals | None = None) -> None:
        super().__init__(target, interrupts)
        self.found = AsFound()
        self.known = KnownState(self.profile, self.guard, self.book, self.report.problems)
        self.restorations = Restorations(self.profile, self.guard, self.report, self.known,
                                         self.found)
        self._power_on_refused = ""                # why the rig did not power the unit on
        self.since_power_on = 0                     # ns: the restart waited out (open_powered)
        #: the simulator keeps a unit just powered on, this long after its power-on
        #: (open_powered with ``kept``; None: none kept)
        self._kept_power_on: int | None = None
        self.restored = False       # the latest open_powered restored the unit kept

    def _guard(self, info: TargetInfo, interrupts: StopSignals) -> Guard:
        return Guard(self.profile, self.target.address, max_travel=info.max_travel,
                     allow_destructive=info.allow_destructive, interrupts=interrupts)

    @property
    def identity(self) -> dict[str, str]:
        """The unit's identity as found (`?`, `Q`)."""
        return self.found.identity

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
        self.book.before = before
        link.meanwhile = meanwhile         # done at the known state's first frames told
        with self.guard.own_frames():
            try:
                self.known.bring(link, tell)
            except StepFailed:
                # answers that did not belong to their frames (answered twice) misled
                # what the known state read: the case gets the link and FAILs on them
                if not link.violations:
                    raise
            finally:
                self.book.before = None
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

    def open_powered(self, *, kept: bool = False,
                     meanwhile: Callable[[], None] | None = None) -> Link | None:
        """A link to the unit just powered on through its rig, in place of the known state:
        the rig's hands off, the power cycled (the guard books it as a restart: counters
        zeroed, the axes where they stand), the restart waited out on the suite's clock
        (no wall time), the checksum mode off as the manuals state the reset state
        (spec 9 [M]). The axes are then taken as standing where the run began: the guard's
        envelope re-centred there, since a co-simulator's axes are numbers, not a machine
        (docs/decisions.md). None where the rig refused `power-on` (the known state
        then, from here on). ``kept``: where the simulator keeps a state (`snapshot`,
        docs/cosim.md), the first unit so powered on is kept and the next ones are that
        one restored (:attr:`restored`): the same reset state without the power-on and
        its wait (for a caller whose units leave nothing behind that a power-on keeps,
        EEPROM bytes and the rig's rate switch: diff puts back what it wrote).
        ``meanwhile``: work of the caller's done once the power-on is asked for, before
        its replies are read (while a simulator that takes commands ahead runs it)."""
        self.start()
        self.guard.check_idle()
        link = self._new_link()
        rig = link.rig
        self.restored = kept and self._kept_power_on is not None
        if self.restored:
            if meanwhile is not None:
                meanwhile()
            link.port.restore()
            rig.forget_hands()             # restored as they were kept: off
            rig.on_power_on()
            link.checksums = False
            self.since_power_on = self._kept_power_on
        else:
            wait = self.profile.restart_ms / 1000 + MARGIN
            try:
                rig.hands_off()
                # a co-simulator that takes commands ahead gets the power-on, the restart
                # and the rig's `state` read next (unless a snapshot comes first) at once
                ahead = getattr(link.port, "power_on_ahead", None)
                if ahead is not None:
                    ahead(wait, state=not kept)
                if meanwhile is not None:
                    meanwhile()
                rig.power_on()
            except CouldNotTest as err:
                self._power_on_refused = str(err)
                return None
            link.checksums = False
            powered = link.now
            link.wait(wait, Spent.MANUAL)
            self.since_power_on = link.now - powered
            snapshot = getattr(link.port, "snapshot", None)
            if kept and snapshot is not None and snapshot():
                self._kept_power_on = self.since_power_on
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
                self.found.identity[name] = ",".join(r.values)
        self.report.identity = self.found.identity
        self.report.line = round_trip(link)
        for n in range(6):
            r = link.send(f"SR{n}")
            if hex_ok(r):
                self.found.status[n] = r.hex()
        self.report.found = {f"ST{n}": "%02X" % v for n, v in self.found.status.items()}
        self.report.found["checksums"] = "on" if self.found.checksums else "off"
        r = link.send("SR6")
        if hex_ok(r) and bits(r) & (St6.RUN | St6.STOP) and not bits(r) & St6.INTA:
            # a unit may hold RUN a while after its last vector (a T dwell): not moving
            dwell = self.profile.range("T").hi / 1000
            r = self.known.rest.await_idle(link, dwell + 2 * MARGIN) or r
        if hex_ok(r):
            st6 = r.hex()
            self.report.found["ST6"] = "%02X" % st6
            if st6 & St6.STOP or (st6 & St6.RUN and not st6 & St6.INTA):
                self.failed = (f"{self.target.info.spec}: the unit reports RUN or STOP "
                               f"(ST6 = {st6:02X}): it is moving, or in hand-wheel (MPG) "
                               "mode; stop it before running the suite")
                self.report.problems.append(self.failed)
                raise SessionError(self.failed)
        self.found.counters = self.known.rest.position(link)
        self.guard.envelope.origin(self.found.counters)
        self.known.way_back.rig_origin = self.known.way_back.rig_physical(link)
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
        self.found.checksums = link.checksums

    def eeprom_as_found(self) -> dict[int, int]:
        if not self.eeprom and "ER" in self.profile.commands:
            with self._own_link() as link:
                self._backup_eeprom(link)
        return self.eeprom

    def _backup_eeprom(self, link: Link) -> None:
        """Every byte the run can write, before its first EEPROM write: all of them."""
        read = read_eeprom(link, list(range(self.profile.eeprom.size)))
        found = {address: r.hex() for address, r in read.items() if hex_ok(r)}
        self.guard.eeprom.found(found)
        missing = self.profile.eeprom.size - len(found)
        if missing:
            self.report.problems.append(f"EEPROM: {missing} bytes could not be read, so "
                                        "they are not written")

    # -- Ctrl-C and the end --------------------------------------------------------------------
    def emergency_stop(self) -> None:
        if self._link is not None:
            self.report.interrupted = True
            wait = None if self.guard.responding else MARGIN
            try:
                with self.guard.emergency():
                    self.known.rest.halt(self._link, timeout=wait, urgent=True)
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
                    self.restorations.restore(link)
            except Interrupted:
                self.emergency_stop()
                self.report.problems.append("restorations stopped by Ctrl-C: what follows "
                                            "was not put back")
                self.restorations.unrestored()
            except (TargetNotResponding, SafetyStop, CouldNotTest) as err:
                self.report.problems.append(f"restorations stopped: {err}")
                self.restorations.unrestored()
            self._keep_log(link)
        # what happened to the unit first: it explains what could not be put back
        self.report.problems[:0] = [str(r) for r in (*self.guard.restarts,
                                                     *self.guard.untracked)]
        self.report.excursion = [list(e) for e in self.guard.excursion()]

    def after_case(self) -> None:
        """EEPROM bytes a case wrote are put back as soon as it ends, so that no later
        case meets them (e.g. 06 turning the GVE114's hand wheel on after a J); the end
        of the run verifies every byte again. The unit is stopped first: a case (or a
        diff sequence) may leave it moving, and a moving unit refuses EEPROM writes."""
        if not self.guard.eeprom.written or self.failed:
            return
        with self._own_link() as link:
            self.known.rest.stop(link)
            self.restorations.eeprom_back(link, sorted(self.guard.eeprom.written))


def open_session(target: Reachable, interrupts: StopSignals | None = None) -> Session:
    """The session ``target`` needs: a real unit's, or the embedded emulator's."""
    return (RealSession if target.info.real else EmuSession)(target, interrupts)
