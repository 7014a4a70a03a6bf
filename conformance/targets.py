"""Targets: where the suite's links go (issue 4 item 1).

``emu:PROFILE`` (the embedded emulator in virtual time, a fresh unit per link;
``emu:GVE84-100?mutant=NAME`` plants a mutant), ``serial:/dev/ttyUSB0?baud=115200&address=0``
and ``tcp:HOST:PORT`` (a unit or a clone's simulator in real time, one shared port put
into a known state before each case). This is the only module of the suite that imports
the emulator, and only to open its ``gve://`` URL.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from urllib.parse import parse_qs, urlsplit

import serial

from conformance.case import TargetInfo
from conformance.link.link import Link
from conformance.link.safety import Guard
from gve_fixtures.profile import Profile, available_profiles, load_profile

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


def known_state(link: Link, profile: Profile) -> None:
    """Put a real unit into the state a case expects (docs/suite.md)."""
    # H first: it is answered even inside an open packet, and discards it (spec 7)
    link.send("H", checksum=True)
    link.send("%-", checksum=True)          # harmless if checksums were off: an error
    link.checksums = False
    r = profile.reset
    for body in (*RESET_SEQUENCE, f"V{r.V}", f"A{r.A}", f"B{r.B}", f"${r.dollar}", f"T{r.T}"):
        link.send(body)                      # a command the unit lacks just answers 3
    link.send("G")                           # clears INTA left by H (6 when none)
    link.send("D")
    link.guard.position = [0, 0, 0, 0]
    link.log.clear()


def parse_target(spec: str, *, profile: str | None = None, allow_destructive: bool = False,
                 max_travel: int = DEFAULT_MAX_TRAVEL, mutant: str | None = None) -> Target:
    kind, _, rest = spec.partition(":")
    if kind == "emu":
        parts = urlsplit("x://h/" + rest)
        name = parts.path.lstrip("/") or "GVE84-100"
        q = parse_qs(parts.query)
        mutant = q.get("mutant", [mutant])[-1]
        p = load_profile(profile or name)
        info = TargetInfo("emu", spec, True, True, True, max_travel)
        return Target(info, p, p.address, p.default_baud, spec, mutant)
    if kind in ("serial", "tcp"):
        if kind == "serial":
            parts = urlsplit("x://h" + (rest if rest.startswith("/") else "/" + rest))
            q = parse_qs(parts.query)
            url = parts.path
        else:
            host, _, q_text = rest.partition("?")
            q = parse_qs(q_text)
            url = f"socket://{host}"
        if profile is None:
            raise ValueError(f"{spec}: say which profile the unit should behave as "
                             f"(--profile, one of {', '.join(available_profiles())})")
        p = load_profile(profile)
        baud = int(q.get("baud", [p.default_baud])[-1])
        address = int(q.get("address", [p.address])[-1])
        info = TargetInfo(kind, spec, False, False, allow_destructive, max_travel)
        return Target(info, p, address, baud, url)
    raise ValueError(f"unknown target {spec!r}: use emu:PROFILE, serial:PATH?baud=&address=, "
                     "or tcp:HOST:PORT")
