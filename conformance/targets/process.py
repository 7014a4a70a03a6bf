"""``exec:COMMAND``: a program the suite starts itself — a firmware clone's simulator, or
the emulator (``exec:python -m emulator --pty``) — judged as a real unit.

The program prints where its serial port is on its first line (docs/rig.md: a pty path,
``socket://HOST:PORT``, ``HOST:PORT`` or ``tcp HOST:PORT``); the port is opened as
port.py opens any other, in real time. When it answers `state` on its standard input with
a JSON object within a second, the control channel is the run's test rig (rig.py) and
rig cases run; otherwise they are COULD-NOT-TEST. A first line ``cosim 1`` instead hands
the program's clock to the suite (docs/cosim.md, cosim.py): the unit runs in virtual
time, the rig's commands part of the same protocol. The program is stopped when the
target is closed (at the end of the run, also after Ctrl-C once the session has halted
the unit), and a program that ends during the run makes the target not responding at
once.

A command that cannot be started, and a program that started and then serves no port —
it ends, says nothing, or its first line is neither a port it can open nor ``cosim N`` —
stop the run before it begins: one line saying why (its bytes escaped), exit status 2,
as a serial port that cannot be opened does; not a COULD-NOT-TEST line per case.
"""

from __future__ import annotations

import shlex
from dataclasses import dataclass, replace
from typing import NoReturn

from conformance.link.signals import StopSignals
from conformance.protocol.bounded import decimal
from conformance.targets.cosim import (
    VERSION,
    CosimLine,
    CosimPort,
    ProtocolBroken,
    announced,
    offered,
)
from conformance.targets.info import TargetInfo
from conformance.targets.port import PortTarget, open_port, real_profile
from conformance.targets.program import Program, ProgramError
from conformance.targets.rig import ControlRig
from conformance.targets.session import Session, SessionError
from conformance.targets.target import Target, TargetError
from conformance.targets.targetport import ENDING_SECONDS, TargetPort
from conformance.verdicts.quoting import shown
from gve_fixtures.profile import available_profiles

#: how long the program may take to print its port
FIRST_LINE_SECONDS = 10.0


def port_url(line: str) -> str | None:
    """The pyserial URL of the port a program's first line names (None: not a port)."""
    text = line.strip()
    if text.startswith("tcp "):
        text = text[4:].strip()
    if text.startswith("/") or "://" in text:
        return text
    host, colon, port = text.rpartition(":")
    number = decimal(port)
    if colon and host and number is not None and 0 < number < 65536 and " " not in host:
        return f"socket://{host}:{port}"
    return None


@dataclass
class ProcessTarget(PortTarget):
    command: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        super().__post_init__()
        self.program: Program | None = None
        self.rig: ControlRig | None = None
        self.unserved = ""          # why the program served no port: the target's fault

    def preflight(self) -> None:
        """Start the program and open its port: one that serves none stops the run
        before it begins, with one line (TargetError), whatever it printed."""
        try:
            self._open()
        except SessionError as err:
            raise TargetError(str(err)) from None

    def begin(self, interrupts: StopSignals | None = None) -> Session:
        session = super().begin(interrupts)
        if self.unserved:
            session.failed = self.unserved
        return session

    def _open(self):
        if self.unserved:
            raise SessionError(self.unserved)
        if self._port is None:
            first = self._start()
            version = announced(first)
            if version is not None:
                self._port = self._cosim(version, offered(first))
                return self._port
            url = self._serve_port(first)
            try:
                self._port = TargetPort(open_port(url, self.baud, self.info.spec),
                                         self.program)
            except TargetError as err:
                self._unserved(f"the program's port cannot be used: {err}")
        return self._port

    def _fail(self, why: str) -> NoReturn:
        self._stop()
        raise TargetError(f"{self.info.spec}: {why}")

    def _unserved(self, why: str) -> NoReturn:
        """The program started and serves no port: the target's fault, not the user's."""
        self._stop()
        self.unserved = f"{self.info.spec}: {why}"
        raise SessionError(self.unserved)

    def _start(self) -> str:
        """Start the program; its first line."""
        try:
            self.program = program = Program(list(self.command))
        except ProgramError as err:
            raise TargetError(f"{self.info.spec}: {err}") from None
        first = program.line(FIRST_LINE_SECONDS)
        if first is None:
            program.wait(ENDING_SECONDS)
            tail = program.stderr_tail()
            self._unserved(f"the program printed no port: {program.ended()}" if not program.alive
                       else f"the program printed no port within {FIRST_LINE_SECONDS:g} s"
                       + (f" (stderr: {shown(tail)})" if tail else ""))
        return first

    def _serve_port(self, first: str) -> str:
        """The port the first line names and the rig on standard input; the port's URL."""
        url = port_url(first)
        if url is None:
            self._unserved(f"the program's first line {shown(first)} is not a port (a pty "
                       "path, socket://HOST:PORT or HOST:PORT) nor cosim 1")
        self.program.read_in_background()              # it never blocks on its output
        self.rig = ControlRig.detect(self.program, self.address, self._restarted)
        self._found_rig(virtual=False)
        return url

    def _cosim(self, version: int, extensions: frozenset[str]) -> CosimPort:
        """The co-simulation's line and port, its rig when `state` answers one. A
        simulator that breaks the protocol here leaves the line broken: the run's first
        frame finds it so (a FAIL), nothing is refused before the run."""
        if version != VERSION:
            self._fail(f"the program speaks co-simulation version {version}; this suite "
                       f"speaks version {VERSION} (docs/cosim.md)")
        line = CosimLine(self.program, self.baud, extensions)   # replies read as they are due
        try:
            self.rig = ControlRig.found_in(line.start(), line.ask, self.address,
                                           self._restarted)
        except ProtocolBroken:
            self.rig = None
        self._found_rig(virtual=True)
        return CosimPort(line)

    def _found_rig(self, *, virtual: bool) -> None:
        self.info = replace(self.info, has_rig=self.rig is not None, virtual_time=virtual)
        named = self.rig.found.get("profile") if self.rig else None
        if named in available_profiles() and named != self.profile.name:
            self._fail(f"--profile {self.profile.name} contradicts the program, whose rig "
                       f"says it behaves as {named}")

    def _restarted(self) -> None:
        """The rig cycled the power: the guard books it as a restart (J)."""
        self.session.guard.restarted()

    def connect(self, address: int | None):
        port, baud, _, _ = super().connect(address)
        return port, baud, self.info.virtual_time, self.rig

    def _stop(self) -> None:
        if self.program is not None:
            self.program.stop()
        self.program = self.rig = None

    def close(self) -> None:
        super().close()
        self._stop()


def parse(kind: str, rest: str, *, spec: str, profile: str | None, allow_destructive: bool,
          max_travel: int, mutant: str | None, strict: bool = False) -> Target:
    try:
        command = shlex.split(rest)
    except ValueError as err:
        raise TargetError(f"{spec}: cannot read the command: {err}") from None
    if not command:
        raise TargetError(f"{spec}: give the command that starts the simulator "
                          "(exec:'./clone-sim --pty')")
    p = real_profile(spec, profile, mutant,
                     "put --mutant NAME in the command when it is the emulator")
    info = TargetInfo(kind, spec, False, False, allow_destructive, max_travel, strict)
    return ProcessTarget(info, p, p.address, p.default_baud, spec, command=tuple(command))
