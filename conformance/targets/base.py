"""A target: the profile expected of it, how to open links to it, and the known state
a real unit is put into before each case (docs/suite.md)."""

from __future__ import annotations

from dataclasses import dataclass, field

import serial

from conformance.case import TargetInfo
from conformance.link.link import Link
from conformance.link.safety import Guard
from gve_fixtures.profile import Profile

DEFAULT_MAX_TRAVEL = 2000


@dataclass
class Target:
    info: TargetInfo
    profile: Profile
    address: int
    baud: int
    url: str
    mutant: str | None = None
    _port: serial.SerialBase | None = None
    links: list[Link] = field(default_factory=list)

    def open_link(self, address: int | None = None) -> Link:
        if self.info.kind == "emu":
            import emulator  # noqa: F401  (registers gve://)
            address = self.address if address is None else address
            query = f"model={self.profile.name}&address={address}"
            if self.mutant:
                query += f"&mutant={self.mutant}"
            port = serial.serial_for_url(f"gve://?{query}", timeout=0.25)
            link = Link(port, address=address, baud=port.line.baud, virtual=True,
                        rig=port.line)
        else:
            if address is not None and address != self.address:
                from conformance.case import CouldNotTest
                raise CouldNotTest(f"needs a unit at address {address}")
            if self._port is None:
                self._port = serial.serial_for_url(self.url, baudrate=self.baud, timeout=0.5)
            guard = Guard(enforce=True, max_travel=self.info.max_travel,
                          allow_destructive=self.info.allow_destructive,
                          axes=len(self.profile.axes))
            link = Link(self._port, address=self.address, baud=self.baud, guard=guard)
            known_state(link, self.profile)
        self.links.append(link)
        return link

    def emergency_stop(self) -> None:
        """Ctrl-C on a real unit: H, then D."""
        if self._port is not None:
            for body in ("H", "D"):
                self._port.write(f"!{self.address}{body}\r".encode())
                self._port.timeout = 5
                self._port.read_until(b"\r")

    def close(self) -> None:
        if self._port is not None:
            self._port.close()
            self._port = None


RESET_SEQUENCE = ("H", "D", "SW0,00", "SW1,00", "SW2,00", "SW3,00", "SW4,00", "SW5,00",
                  "XM100", "VN", "N")


def known_axis_limits(profile: Profile) -> tuple[int, ...]:
    """The VL a real unit is put back to: the reset VL (the variant's maximum) where VL's
    range reaches it, else the top of the range (only J restores more, spec 9, 10)."""
    top = profile.range("VL").hi
    return tuple(min(v, top) for v in profile.reset.VL)


def known_state(link: Link, profile: Profile) -> None:
    """Put a real unit into the state a case expects (docs/suite.md)."""
    # H first: it is answered even inside an open packet, and discards it (spec 7)
    link.send("H", checksum=True)
    link.send("%-", checksum=True)          # harmless if checksums were off: an error
    link.checksums = False
    r = profile.reset
    # modal parameters a case may have changed, back to the reset state (spec 9)
    modal = [f"V{r.V}", f"A{r.A}", f"B{r.B}", f"${r.dollar}", f"T{r.T}"]
    if "VL" in profile.commands:
        modal.append("VL" + ",".join(str(v) for v in known_axis_limits(profile)))
    if profile.microstep is not None:
        modal += [f"M{profile.microstep.reset_mode}", f"M{profile.microstep.reset_current}"]
    for body in (*RESET_SEQUENCE, *modal):
        link.send(body)                      # a command the unit lacks just answers 3
    link.send("G")                           # clears INTA left by H (6 when none)
    link.send("D")
    link.guard.position = [0, 0, 0, 0]
    link.log.clear()
