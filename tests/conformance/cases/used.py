"""A used unit for the cases' tests: the emulator in process and in virtual time, judged
as a real unit (a ``serial:`` target with no rig, one unit for the whole run, the
session's guard and known state), after an owner has used it: the index elsewhere, the
EEPROM holding the owner's bytes, the axes moved away and the counters set elsewhere,
input polarities set and the checksum mode left on.
A case that assumes a fresh unit FAILs here although the unit is correct."""

from __future__ import annotations

import serial

import emulator  # noqa: F401  (registers gve://)
from conformance.case.context import TargetInfo
from conformance.targets.port import PortTarget
from conformance.targets.target import DEFAULT_MAX_TRAVEL
from gve_fixtures.profile import load_profile

#: the owner's EEPROM bytes (address: byte), none as shipped
OWNER_EEPROM = {0x01: 0x02, 0x0D: 0x07, 0x10: 0x12, 0x40: 0xA5, 0x4C: 0x07, 0xFD: 0x33}
#: bytes that change what a family does on the line: left as shipped there (the GVE114's
#: 06 turns the hand wheel on, its 0D sets the baud rate after a restart)
ON_THE_LINE = {"GVE114": {0x06, 0x0D}}
#: frames that moved the index (modulo 256) before the run
FRAMES_BEFORE = 300


class UsedUnit(PortTarget):
    """One emulated unit in virtual time behind a ``serial:`` target."""

    def __post_init__(self) -> None:
        super().__post_init__()
        self.port = serial.serial_for_url(self.url, timeout=0.5)

    def _open(self):
        return self.port

    def connect(self, address: int | None):
        port, baud, _, _ = super().connect(address)
        return port, baud, True, None

    def close(self) -> None:
        """The one unit stays for the whole test."""

    def send(self, body: str) -> bytes:
        self.port.write(b"!%d%s\r" % (self.address, body.encode()))
        return self.port.read_until(b"\r")

    def use(self) -> None:
        """What an owner leaves behind (the frames a unit takes as it is shipped)."""
        for _ in range(FRAMES_BEFORE):
            assert self.send("V1000") == b"0\r"
        for address, byte in OWNER_EEPROM.items():
            if address in ON_THE_LINE.get(self.profile.family, ()):
                continue
            assert self.send("EW%02X,%02X" % (address, byte)) == b"0\r"
        assert self.send("V5000") == b"0\r"
        assert self.send("L700,-600,500") == b"0\r"
        self.port.line.advance(2.0)
        if "NX" in self.profile.commands:
            assert self.send("NX12345") == b"0\r" and self.send("NZ-777") == b"0\r"
        assert self.send("V1000") == b"0\r"
        assert self.send("SW2,2B") == b"0\r"        # the owner's input polarities
        if "%" in self.profile.commands:             # and the checksum mode left on
            assert self.send("%+") == b"0,5C\r"

    def state(self) -> dict:
        return self.port.line.state()


def used_unit(profile: str, *, allow_destructive: bool = False,
              max_travel: int = DEFAULT_MAX_TRAVEL, readings: tuple[str, ...] = (),
              mutant: str | None = None) -> UsedUnit:
    p = load_profile(profile)
    url = f"gve://?model={profile}" + (f"&reading={','.join(readings)}" if readings else "") \
        + (f"&mutant={mutant}" if mutant else "")
    info = TargetInfo("serial", f"serial:{url} (used)", False, False, allow_destructive,
                      max_travel)
    unit = UsedUnit(info, p, p.address, p.default_baud, url)
    unit.use()
    return unit
