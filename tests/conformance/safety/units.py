"""Real-unit targets for the safety tests without a pty: the emulator in process on the
wall clock (``gve://...&realtime=1``) behind a ``serial:``-like target, so the session
treats it as a real unit, and a recorder of every byte the suite writes (with a hook per
frame, e.g. to press Ctrl-C while that frame is in flight). Its rig tells where the axes
physically went (``state()['excursion']``)."""

from __future__ import annotations

from collections.abc import Callable

import serial

import emulator  # noqa: F401  (registers gve://)
from conformance.case.context import TargetInfo
from conformance.targets.port import PortTarget
from conformance.targets.rig import ControlRig
from conformance.verdicts.verdict import CouldNotTest
from emulator.link.control import handle
from gve_fixtures.profile import load_profile


class Recorder:
    """A pyserial port that records the frames written through it."""

    def __init__(self, port, on_frame: Callable[[int, bytes], None] | None = None) -> None:
        self._port = port
        self.on_frame = on_frame
        self.frames: list[bytes] = []
        self._partial = b""

    def write(self, data: bytes) -> int:
        self._partial += data
        while b"\r" in self._partial:
            line, _, self._partial = self._partial.partition(b"\r")
            start = line.rfind(b"!")
            if start >= 0:
                self.frames.append(line[start:] + b"\r")
                if self.on_frame:
                    self.on_frame(len(self.frames) - 1, self.frames[-1])
        return self._port.write(data)

    def __getattr__(self, name):
        return getattr(self._port, name)

    def __setattr__(self, name, value):
        if name == "timeout":
            self._port.timeout = value
        else:
            super().__setattr__(name, value)


class InProcessUnit(PortTarget):
    """The emulator in process on the wall clock, judged as a real unit."""

    on_frame: Callable[[int, bytes], None] | None = None

    def __post_init__(self) -> None:
        super().__post_init__()
        self.recorder = Recorder(serial.serial_for_url(self.url, timeout=0.5),
                                 lambda i, f: self.on_frame and self.on_frame(i, f))
        self.line = self.recorder._port.line

    def _open(self):
        self._port = self.recorder            # one unit for the whole test, never closed
        return self._port

    def close(self) -> None:
        self._port = None

    @property
    def frames(self) -> list[bytes]:
        return self.recorder.frames

    def state(self) -> dict:
        return self.line.state()


def in_process_unit(profile: str = "GVE84-100", *, max_travel: int = 2000,
                    allow_destructive: bool = False, eeprom: str | None = None,
                    readings: tuple[str, ...] = ()) -> InProcessUnit:
    p = load_profile(profile)
    url = f"gve://?model={profile}&realtime=1" + (f"&eeprom={eeprom}" if eeprom else "") \
        + (f"&reading={','.join(readings)}" if readings else "")
    info = TargetInfo("serial", f"serial:{url}", False, False, allow_destructive, max_travel)
    return InProcessUnit(info, p, p.address, p.default_baud, url)


class VirtualUnit(PortTarget):
    """The emulator in process in virtual time, judged as a real unit (its session
    guards, restores and books every frame), its line the rig: what a co-simulator is,
    without a process. ``unit`` is the emulator's unit (tests may reach inside it)."""

    with_rig = True

    def __post_init__(self) -> None:
        super().__post_init__()
        self._keep = serial.serial_for_url(self.url, timeout=0.25)
        self.line = self._keep.line
        self.unit = self.line.units[0]
        # the rig over the emulator's control channel, as an exec: target's is
        self.rig = ControlRig(lambda command: handle(self.line, command), self.line.state(),
                              self.address, self._power_cycled)

    def _power_cycled(self) -> None:
        self.session.guard.restarted()

    def connect(self, address: int | None):
        if address is not None and address != self.address:
            raise CouldNotTest(f"needs a unit at address {address}")
        return self._keep, self.line.baud, True, self.rig if self.with_rig else None

    def close(self) -> None:
        return None

    def state(self) -> dict:
        return self.line.state()


def virtual_unit(profile: str = "GVE84-100", *, max_travel: int = 2000,
                 allow_destructive: bool = False, rig: bool = True,
                 readings: tuple[str, ...] = (), mutant: str | None = None) -> VirtualUnit:
    p = load_profile(profile)
    url = f"gve://?model={profile}" + (f"&reading={','.join(readings)}" if readings else "") \
        + (f"&mutant={mutant}" if mutant else "")
    info = TargetInfo("serial", f"virtual:{profile}", True, rig, allow_destructive, max_travel)
    unit = VirtualUnit(info, p, p.address, p.default_baud, url)
    unit.with_rig = rig
    return unit
