"""The restorations at the end of a run on a real unit: the unit stopped, what cannot be
read set to the reset state, the axes back where the run began, the position counters,
EEPROM and status words put back and verified by reading back, the checksum mode as
found; what could not be restored goes into the session's report as a problem, and
"restored" is said only of what was."""

from __future__ import annotations

from conformance.known_state.answers import hex_ok, refused_range, shown, shown_counters, taken
from conformance.known_state.procedure import KnownState
from conformance.link.account import Spent
from conformance.link.framing import Response
from conformance.link.link import MARGIN, Link
from conformance.link.liveness import TargetNotResponding
from conformance.link.safety import Guard
from conformance.targets.as_found import AsFound, read_eeprom
from conformance.targets.session_report import SessionReport
from conformance.verdicts.verdict import CouldNotTest
from gve_fixtures.profile import Profile
from gve_fixtures.protocol import ErrorCode

#: status words restored at the end, polarity before causes before enables (an enable
#: written last finds its polarity and cause already in place)
RESTORE_ORDER = (2, 3, 4, 5, 0, 1)


class Restorations:
    """Putting back what the run changed of the unit ``found`` (also EEPROM bytes a case
    wrote, as soon as it ends), with the known state's stop and way back."""

    def __init__(self, profile: Profile, guard: Guard, report: SessionReport,
                 known: KnownState, found: AsFound) -> None:
        self.profile = profile
        self.guard = guard
        self.report = report
        self.known = known
        self.rest = known.rest
        self.way_back = known.way_back
        self.found = found

    @property
    def eeprom(self) -> dict[int, int]:
        """The EEPROM bytes as found (the guard's ledger holds them)."""
        return self.guard.eeprom.originals

    def restore(self, link: Link) -> None:
        if not self.guard.responding:
            self.report.not_responding = "the target stopped responding"
            with self.guard.emergency():              # once, without waiting long
                self.rest.halt(link, timeout=MARGIN, urgent=True)
                link.send("D")
            raise TargetNotResponding("the target is not responding")
        left, answers = self.known.settle(link)
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
        frames = self.rest.reset_frames()
        took = [body for body in frames if taken(answers.get(body))]
        # M114 12: "Pokud je hodnota některého parametru mimo rozsah, není možné MPG
        # použít": the MPG mode refused out of range where the EEPROM does not allow it
        # is that unit's reset state, nothing left to set
        inert = [body for body in frames if body.startswith("Y") and self.rest.has_mpg()
                 and refused_range(answers.get(body))]
        refused = [f"{body} answered {shown(answers.get(body))}" for body in frames
                   if body not in took and body not in inert]
        if took:
            self.report.reset.append("set to the reset state, each answered 0 (they cannot "
                                     "be read back): " + ", ".join(took))
        if inert:
            self.report.reset.append("the MPG mode left as the unit's EEPROM makes it (the "
                                     "MPG not allowed there): " + ", ".join(
                                         f"{b} answered {shown(answers.get(b))}" for b in inert))
        if refused:
            self.report.problems.append("not set to the reset state: " + "; ".join(refused))
        micro = self.profile.microstep
        if micro and all(f"M{m}" in took for m in (micro.reset_mode, micro.reset_current)):
            self.report.reset.append("GVE54 micro-step mode and current set to "
                                     f"M{micro.reset_mode}, M{micro.reset_current} (the reset "
                                     "state)")

    def _restore_axes(self, link: Link) -> None:
        """The axes back where the run began, as the counters then read; where they are
        not, a problem saying where they are. An axis no position read shows (the
        GVE114's A: PF reads X, Y, Z, M114 13.6.6) cannot be verified: said as such."""
        names = self.profile.axes
        stopped = self.guard.interrupts.stopped
        if self.guard.recentred and not stopped:
            # a co-simulator in virtual time, its envelope re-centred at every power-on
            # start: nothing physical moved, so nothing is brought back (nor said restored)
            where = self.way_back.rig_physical(link)
            self.report.reset.append(
                "the co-simulator's axes left where its last sequence put them"
                + (f" ({shown_counters(where)} counter units from where it started, by its rig)"
                   if where else "")
                + ": its envelope was re-centred at every power-on start, nothing physical "
                  "moving in virtual time")
            return
        if not stopped and None in self.guard.envelope.position():
            self.way_back.relocate(link)
        body, read = "", {}
        if stopped or self.guard.lost:
            read = self.rest.position(link)
        else:
            try:
                body, read = self.way_back.go_back(link)
            except CouldNotTest as err:
                self._axes_left(str(err))
                return
        here = self.guard.envelope.position()
        pf_axes = min(3, len(names))
        away = [a for a, h in zip(names[:pf_axes], here, strict=False) if h != 0]
        if away:
            unknown = [a for a, h in zip(names, here, strict=True) if h is None]
            self._axes_left("no motion after a signal" if stopped else
                            f"no motion after it: {self.guard.lost}" if self.guard.lost else
                            f"where {', '.join(unknown)} stand is not known exactly" if unknown
                            else "the way back would have left the envelope")
            return
        if self.guard.recentred and self.way_back.rig_origin is None:
            self._axes_left("the envelope was re-centred at each power-on of the "
                            "co-simulator, and its rig has no eyes to say where they are")
            return
        moved = (f"moved back with {body} at V{self.profile.reset.V}" if body else
                 "no motion after the signal" if stopped else "no move needed")
        which = "" if pf_axes == len(names) else f" {', '.join(names[:pf_axes])}"
        self.report.restored.append(f"axes{which} back where the run began ({moved}); PF then "
                                    f"read {shown_counters(read)}, where the frames put them")
        for i in range(pf_axes, len(names)):
            if here[i] != 0:
                self.report.reset.append(
                    f"axis {names[i]} not verified: no position read shows it (PF reads "
                    f"{', '.join(names[:pf_axes])}), and the frames leave it anywhere in "
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
        if not self.found.counters:
            self.report.problems.append("position counters not restored: PF could not be "
                                        "read before the run")
            return
        if self.guard.recentred and not any(self.found.counters.values()):
            # a co-simulator found with its power-on counters: powered on once more, as
            # every sequence began, they read as found (or the problem says what they read)
            link.rig.power_on()
            link.checksums = False
            link.wait(self.profile.restart_ms / 1000 + MARGIN, Spent.MANUAL)
            self.guard.recentre()
            read = self.rest.position(link)
            if read == self.found.counters:
                self.report.restored.append(f"position counters as found: PF reads "
                                            f"{shown_counters(read)} (the co-simulator powered on "
                                            "as every sequence began)")
            else:
                self.report.problems.append(f"position counters not restored: after a "
                                            f"power-on PF read {shown_counters(read)}")
            return
        here = self.guard.envelope.position()
        unknown = [names[i] for i in self.found.counters if here[i] is None]
        if unknown:
            self.report.problems.append(
                f"position counters {', '.join(unknown)} not restored: where the axes "
                "stand is not known exactly, so the counts found cannot be carried to them")
        wanted = {i: c + int(here[i]) for i, c in self.found.counters.items()
                  if here[i] is not None}
        settable = {i: v for i, v in wanted.items() if f"N{names[i]}" in self.profile.commands}
        sent = [f"N{names[i]}{v}" for i, v in settable.items()]
        for body in sent:
            self.rest.when_idle(link, body)
        read = self.rest.position(link)
        found = shown_counters(self.found.counters)
        if any(read.get(i) != v for i, v in settable.items()):
            self.report.problems.append(
                f"position counters not restored: {', '.join(sent)} sent, PF then read "
                f"{shown_counters(read)}")
        elif any(read.get(i) != v for i, v in wanted.items()):
            # no N<axis> (the GVE54): left as the run's N set them where it began
            self.report.reset.append(
                f"position counters left reading {shown_counters(read)} (found {found}; the "
                f"{self.profile.name} has no N<axis> to set them)")
        elif wanted == self.found.counters:
            self.report.restored.append(f"position counters as found: PF reads "
                                        f"{shown_counters(read)}"
                                        + (f" (set with {', '.join(sent)})" if sent else ""))
        elif wanted:
            self.report.restored.append(
                f"position counters count from where they did before the run (found {found}, "
                f"the axes now {self.guard.whereabouts()} full steps from there): "
                f"{', '.join(sent)}; PF reads {shown_counters(read)}")

    def eeprom_back(self, link: Link, addresses: list[int]) -> list[str]:
        """Read ``addresses``, write back those that differ from the originals and read
        them again; returns those written back (a failure is a problem)."""
        changed = []
        read = read_eeprom(link, addresses)
        for address in addresses:
            value = self.eeprom[address]
            r = read[address]
            if hex_ok(r) and r.hex() == value:
                continue
            self.rest.when_idle(link, "EW%02X,%02X" % (address, value))
            r = link.send("ER%02X" % address)
            if hex_ok(r) and r.hex() == value:
                changed.append("%02X" % address)
            else:
                self.report.problems.append(f"EEPROM {address:02X} not restored to {value:02X}: "
                                            f"written back, ER{address:02X} then answered "
                                            f"{shown(r)}")
        self.guard.eeprom.put_back(addresses)
        return changed

    def _restore_eeprom(self, link: Link) -> None:
        if not self.guard.eeprom.ever_written:
            return
        before = len(self.report.problems)
        changed = self.eeprom_back(link, sorted(self.eeprom))
        wrong = len(self.report.problems) - before
        self.report.restored.append(
            f"EEPROM: {len(self.eeprom) - wrong} of {len(self.eeprom)} bytes verified, read "
            "back as found" + (f" ({' '.join(changed)} written back first)" if changed else ""))

    def _restore_status(self, link: Link) -> None:
        for n in RESTORE_ORDER:
            if n in self.found.status:
                link.send("SW%d,%02X" % (n, self.found.status[n]))
        wrong = []
        for n, value in sorted(self.found.status.items()):
            r = link.send(f"SR{n}")
            if not (hex_ok(r) and r.hex() == value):
                wrong.append(f"SR{n} answered {shown(r)}, found {value:02X}")
        wrong += [f"ST{n} could not be read before the run, left 00" for n in range(6)
                  if n not in self.found.status]
        if wrong:
            self.report.problems.append("status words not restored: " + "; ".join(wrong))
        elif self.found.status:
            self.report.restored.append("ST0..ST5 written back and read back as found: "
                                        + " ".join("%02X" % v for _, v in
                                                   sorted(self.found.status.items())))

    def _restore_checksums(self, link: Link) -> None:
        """The checksum mode as found (the known state left it off), read back as it was
        found: `?` without a checksum is refused (4) in the mode (spec 6)."""
        if self.found.checksums:
            r = link.send("%+", checksum=False)
            if r is None or not r.ok:
                self.report.problems.append(f"checksum mode not turned back on: %+ answered "
                                            f"{shown(r)}")
                return
        r = link.send("?", checksum=False)
        on = r is not None and r.code == ErrorCode.SYNTAX
        off = r is not None and r.ok
        if on if self.found.checksums else off:
            self.report.restored.append(
                "checksum mode " + ("back on: %+ answered, then ? without a checksum was "
                                    "refused (4)" if self.found.checksums else
                                    "off as found: ? without a checksum answered"))
        else:
            self.report.problems.append(
                f"checksum mode not {'on' if self.found.checksums else 'off'} as found: ? without "
                f"a checksum answered {shown(r)}")

    def unrestored(self) -> None:
        if not any(line.startswith("axes") for line in self.report.restored + self.report.problems):
            self._axes_left("the restorations stopped before")
        if self.guard.eeprom.written:
            written = sorted(self.guard.eeprom.written)
            self.report.problems.append("EEPROM not verified: bytes written by the run: "
                                        + " ".join("%02X" % a for a in written))
        if self.found.status:
            self.report.problems.append("status words not verified as found: " + " ".join(
                f"ST{n}={v:02X}" for n, v in sorted(self.found.status.items())))
