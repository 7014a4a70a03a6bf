"""One emulated GVE unit: bytes in, bytes out, at instants (docs/architecture.md).

The unit frames the byte stream itself (framer.py), checks address and checksum,
counts the index, keeps the history for `>`, collects packets, dispatches the other
commands through the table in commands.py and answers through ``emit``. Motion is the
stepper core's (emulator.motion); the unit only captures modal parameters into vectors.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any, ClassVar

from emulator.motion import create
from emulator.motion.interface import Vector
from emulator.mutants import Mutant
from emulator.protocol.checksum import checksum
from emulator.protocol.commands import (
    COMMANDS,
    FULL,
    UNKNOWN,
    WATCHDOG,
    Deferred,
    _steps,
    cmd_spindle,
    split,
)
from emulator.protocol.eeprom import Eeprom
from emulator.protocol.framer import Framer
from emulator.protocol.params import RANGE, SYNTAX, CommandError, dec
from emulator.protocol.response import response
from emulator.protocol.state import INTA, RUN, STOP, UnitState, reset_state
from gve_fixtures.profile import Profile, load_profile

MS = 1_000_000
MAX_FRAME = 96
_HEX = frozenset(b"0123456789ABCDEFabcdef")
# inside an open packet these are executed at once (and close the packet); spec 7
_PACKET_BREAKERS = frozenset(("H", "@", ">", "J", "*S", "*E"))


def _discard(data: bytes, t: int) -> None:
    pass


class Unit:
    def __init__(self, profile: Profile | str | Path, address: int | None = None, *,
                 eeprom_path: str | Path | None = None, mutant: str | None = None,
                 watchdog_ms: int | None = None, stepper: str | None = None,
                 origin: int = 0) -> None:
        if not isinstance(profile, Profile):
            profile = load_profile(profile)
        self.profile = profile
        self.address = profile.address if address is None else address
        self.addresses = {self.address}
        if profile.spindle is not None and self.address == 0:
            self.addresses.add(profile.spindle.address)
        self.mutant = Mutant(mutant)
        self.stepper = stepper
        wd = profile.watchdog_ms if watchdog_ms is None else watchdog_ms
        self.framer = Framer(None if self.mutant.active("watchdog-never") else wd * MS)
        self.eeprom = Eeprom(profile.eeprom.image(), eeprom_path)
        self.switches: dict[str, int | None] = {}
        self.emit: Callable[[bytes, int], None] = _discard
        self.now = origin
        self._deaf_until = origin
        self._reset(origin)

    # -- reset ----------------------------------------------------------------------------
    def _reset(self, t: int) -> None:
        p = self.profile
        self.state: UnitState = reset_state(p)
        if not hasattr(self, "motion"):
            scale = p.position_scale if p.microstep is not None else 1
            self.motion = create(len(p.axes), p.max_rate * scale, stepper=self.stepper)
        # the same axes after a restart: the queue is gone and the counters read 0, but
        # nothing moves (the physical position and the excursion go on)
        self.motion.clear(t)
        for axis in range(len(p.axes)):
            self.motion.set_position(axis, 0, t)
        self.motion.set_multiplier(self.state.xm, t)
        self.framer.reset()
        self._pending: list[tuple[bytes, Deferred]] = []

    def power_on(self, t: int) -> None:
        """Power cycle: the reset state; bytes are lost until the restart ends."""
        self.advance(t)
        self._reset(t)
        self._deaf_until = t + self.profile.restart_ms * MS

    # -- derived state ----------------------------------------------------------------------
    def factor(self) -> int:
        """Counter units per commanded step (GVE54 micro-stepping, spec 10.7)."""
        ms = self.profile.microstep
        return ms.factors[self.state.microstep] if ms is not None else 1

    def st6(self, t: int) -> int:
        flags = self.motion.flags(t)
        value = self.state.status[6] & ~(RUN | STOP)
        if flags.busy or self.mpg_active() or self.state.reference_until > t:
            value |= RUN
        if flags.stopping:
            value |= STOP
        return value

    def moving(self, t: int) -> bool:
        return self.motion.flags(t).moving or self.state.reference_until > t

    def mpg_active(self) -> bool:
        mpg = self.profile.mpg
        return (mpg is not None and self.state.mpg in ("+", "&")
                and self.eeprom.read(mpg.enable_address)[0] in mpg.enabling_values)

    def positions(self, t: int) -> tuple[int, ...]:
        here = self.motion.position(t)
        if self.mutant.active("position-ignores-microstep"):
            f = self.factor()
            return tuple(int(x / f) for x in here)
        return here

    def reference_switch(self, axis: str, here: int) -> tuple[int, bool] | None:
        """The axis's reference switch for W (spec 10 W [D]): (physical position, whether
        it releases when the axis backs off). A virtual switch placed by the rig releases
        one step back; the axis's reference input, when it is active now, is a level the
        rig holds: it is here and stays active however the axis moves."""
        if self.switches.get(axis) is not None:
            return self.switches[axis], True
        bit = self.profile.reference_inputs.get(axis)
        if bit is not None:
            level = (self.state.inputs[1] >> bit) & 1
            if level == (self.state.status[2] >> bit) & 1:
                return here, False
        return None

    def push(self, steps: tuple[int, ...], continuous: bool, t: int) -> None:
        m, mr = self.state.modal, self.profile.max_rate
        f = self.factor()
        vector = Vector(
            steps=tuple(s * f for s in steps), continuous=continuous,
            velocity=min(m.V, mr) * f, accel=m.A * 1000 * f, brake=min(m.B, mr) * f,
            short=m.dollar * f, dwell=m.T * MS, path_speed=m.VK,
            axis_limits=tuple(min(v, mr) * f for v in m.VL))
        self.motion.push(vector, t)

    # -- inputs and interrupts (spec 10.3) ----------------------------------------------------
    def check_inputs(self, t: int) -> None:
        s, p = self.state, self.profile
        active1 = ~(s.inputs[1] ^ s.status[2]) & 0xFF
        active2 = ~(s.inputs[2] ^ s.status[3]) & 0xFF
        hit1 = s.status[0] & active1 & p.low_mask
        hit2 = s.status[1] & active2 & p.high_mask
        if not (hit1 or hit2) or self.mutant.active("interrupt-ignored"):
            return
        s.status[4] |= hit1
        s.status[5] |= hit2
        if not s.inta:
            s.status[6] |= INTA
            self.motion.halt(t)

    def set_input(self, port: int, value: int, t: int) -> None:
        self.advance(t)
        self.state.inputs[port] = value & 0xFF
        self.check_inputs(t)

    def set_switch(self, axis: str, position: int | None) -> None:
        self.switches[axis] = position

    # -- time -------------------------------------------------------------------------------
    def next_deadline(self) -> int | None:
        now, best = self.now, None
        for c in (self.framer.deadline(), self.motion.next_event(), self._deaf_until):
            if c is not None and c > now and (best is None or c < best):
                best = c
        for _, d in self._pending:
            if d.instant > now and (best is None or d.instant < best):
                best = d.instant
        return best

    def advance(self, t: int) -> None:
        if not self._pending and self.framer.buf is None:
            if t > self.now:
                self.now = t
            return
        while True:
            expiry = self.framer.deadline()
            answer = min((d.instant for _, d in self._pending), default=None)
            due = min((x for x in (expiry, answer) if x is not None and x <= t), default=None)
            if due is None:
                break
            if due == expiry:
                dropped = self.framer.expire(due)
                if dropped is not None:
                    self._watchdog(dropped[0], due)
            else:
                self._finish_pending(due)
        if t > self.now:
            self.now = t

    def _finish_pending(self, t: int) -> None:
        still = []
        for raw, d in self._pending:
            if d.instant <= t:
                code, values = d.finish(d.instant)
                self._answer(raw, code, values, d.instant)
            else:
                still.append((raw, d))
        self._pending = still

    def _watchdog(self, frame: bytes, t: int) -> None:
        if len(frame) < 2 or self._address(frame) is None:
            return                                  # only '!' arrived, or not ours
        self._answer(frame, WATCHDOG, [], t, remember=False)

    # -- bytes in ---------------------------------------------------------------------------
    def receive(self, data: bytes, t: int, byte_ns: int) -> None:
        i, n = 0, len(data)
        while i < n:
            at = t + i * byte_ns
            if at < self._deaf_until:                 # restarting: these bytes are lost
                i = max(i + 1, -(-(self._deaf_until - t) // byte_ns)) if byte_ns else n
                self.framer.reset()
                continue
            self.advance(at)
            frame, i, end = self.framer.step(data, i, t, byte_ns)
            if frame is not None:
                self.advance(end)
                self._frame(frame, end)

    def _address(self, frame: bytes) -> int | None:
        a = frame[1] - 48 if len(frame) > 1 else -1
        if a in self.addresses:
            return a
        if 0 <= a <= 7 and self.mutant.active("wrong-address-answers"):
            return self.address
        return None

    def _frame(self, raw: bytes, t: int) -> None:
        address = self._address(raw)
        if address is None:
            return
        s = self.state
        if self._pending and raw[2:3] != b"H":
            return                 # an H or W answer is due: other frames are dropped [D]
        body = raw[2:]
        if s.checksums:
            summed = (len(raw) >= 5 and raw[-3] == 0x2C and raw[-2] in _HEX
                      and raw[-1] in _HEX)
            good = summed and checksum(raw[:-2], comma=not self.mutant.active(
                "checksum-no-comma")) == int(raw[-2:], 16)
            if summed and self.mutant.active("checksum-unchecked"):
                good = True
            if not good:
                if s.packet is not None and raw[2:4] not in (b"*S", b"*E"):
                    s.packet.append(("?", "", SYNTAX))
                else:
                    self._answer(raw, SYNTAX, [], t)
                return
            body = raw[2:-3]
        text = body.decode("latin-1")
        if self.mutant.active("lower-case-command"):
            text = text.upper()
        name, params = split(text)
        # every intact frame counts except @ and > themselves (spec 8)
        if name not in ("@", ">") or self.mutant.active("index-counts-queries"):
            s.index = (s.index + 1) & 0xFF
        if len(raw) > MAX_FRAME:
            self._answer(raw, SYNTAX, [], t)
            return
        allowed = name is not None and (
            name in self.profile.commands if address == self.address
            else name in self.profile.spindle.commands)       # type: ignore[union-attr]
        if s.packet is not None and name not in _PACKET_BREAKERS:
            self._member(name if allowed else None, params)
            return
        if name in ("H", "@", ">", "J"):
            s.packet = None
        if not allowed:
            self._answer(raw, UNKNOWN, [], t)
            return
        special = self._SPECIAL.get(name)  # type: ignore[arg-type]
        if special is not None:
            special(self, raw, params, t)
            return
        handler = cmd_spindle if (name == "V" and address != self.address) else COMMANDS[name]
        try:
            result = handler(self, params, t)
        except CommandError as err:
            code = err.code
            if code == RANGE and self.mutant.active("range-error-code"):
                code = SYNTAX
            self._answer(raw, code, [], t)
            return
        if isinstance(result, Deferred):
            self._pending.append((raw, result))
            return
        self._answer(raw, 0, result, t)

    def _answer(self, raw: bytes, code: int, values: list[str], t: int, *,
                remember: bool = True, summed: bool | None = None) -> None:
        s = self.state
        if code and self.mutant.active("index-skips-refused") and remember:
            s.index = (s.index - 1) & 0xFF
        data = response(
            code, values,
            inta=s.inta and not self.mutant.active("inta-bit-missing"),
            summed=s.checksums if summed is None else summed,
            comma=not self.mutant.active("checksum-no-comma"),
            lower=self.mutant.active("checksum-lower-case"))
        if remember:
            s.history = (raw, data)
        self.emit(data, t)

    # -- the commands the unit answers itself ------------------------------------------------
    def _index(self, raw: bytes, params: str, t: int) -> None:
        self._answer(raw, 0, [str(self.state.index)], t, remember=False)

    def _repeat(self, raw: bytes, params: str, t: int) -> None:
        s = self.state
        if params:
            self._answer(raw, SYNTAX, [], t, remember=False)
            return
        if s.history is None:
            self._answer(raw, 0, [], t, remember=False)
            return
        last, answer = s.history
        if self.mutant.active("repeat-reexecutes"):
            silent, self.emit = self.emit, _discard
            try:
                self._frame(last, t)
            finally:
                self.emit = silent
            s.history = (last, answer)
        self.emit(last + b"\r" + answer, t)

    def _restart(self, raw: bytes, params: str, t: int) -> None:
        if params:
            self._answer(raw, SYNTAX, [], t)
            return
        self.emit(b"0\r", t)                  # plain, as after the reset [D]
        self._reset(t)
        self._deaf_until = t + self.profile.restart_ms * MS

    def _checksum_mode(self, raw: bytes, params: str, t: int) -> None:
        if params == "+":
            self.state.checksums = True
        elif params == "-":
            self.state.checksums = False
        else:
            self._answer(raw, SYNTAX, [], t)
            return
        self._answer(raw, 0, [], t)

    def _packet_start(self, raw: bytes, params: str, t: int) -> None:
        if params:
            self._answer(raw, SYNTAX, [], t)
            return
        self.state.packet = []                # no response; a second *S restarts it

    def _member(self, name: str | None, params: str) -> None:
        code = 0
        if name is None:
            code = UNKNOWN
        elif name not in ("C", "B"):
            code = SYNTAX
        else:
            try:
                if name == "C":
                    params = _steps(self, params)  # type: ignore[assignment]
                else:
                    r = self.profile.ranges["B"]
                    params = dec(params, r.lo, r.hi)  # type: ignore[assignment]
            except CommandError as err:
                code = err.code
        self.state.packet.append((name, params, code))  # type: ignore[union-attr]

    def _packet_end(self, raw: bytes, params: str, t: int) -> None:
        s = self.state
        members, s.packet = s.packet, None
        if members is None:
            self._answer(raw, SYNTAX, ["0"], t)
            return
        k = len(members)
        try:
            n = dec(params, 0, 1 << 30)
        except CommandError as err:
            self._answer(raw, err.code, [str(k)], t)
            return
        code = 0
        if k != n and not self.mutant.active("packet-count-ignored"):
            code = WATCHDOG
        if not code:
            code = next((c for _, _, c in members if c), 0)
        vectors = sum(1 for name, _, c in members if name == "C" and not c)
        if not code and vectors:
            if s.kept_single:
                code = SYNTAX
            elif self.mpg_active():
                code = 7
            elif self.motion.queued(t) + vectors > self.profile.buffer:
                code = FULL
        if code == 0 or self.mutant.active("packet-partial-commit"):
            room = self.profile.buffer - self.motion.queued(t)
            for name, value, c in members:
                if c:
                    continue
                if name == "B":
                    s.modal.B = value
                elif room > 0:
                    self.push(value, True, t)
                    room -= 1
        self._answer(raw, code, [str(k)], t)

    _SPECIAL: ClassVar[dict[str, Callable[[Unit, bytes, str, int], None]]] = {
        "@": _index, ">": _repeat, "J": _restart, "%": _checksum_mode,
        "*S": _packet_start, "*E": _packet_end,
    }

    # -- the rig's view --------------------------------------------------------------------------
    def snapshot(self, t: int) -> dict[str, Any]:
        """The unit's state as one JSON-serializable dict (the control channel's `state`).

        (The contract's ``state(t)``: ``state`` here is the protocol state itself.)"""
        self.advance(t)
        s, m = self.state, self.state.modal
        return {
            "profile": self.profile.name,
            "addresses": sorted(self.addresses),
            "time_ns": t,
            "position": list(self.motion.position(t)),
            "physical": list(self.motion.physical(t)),
            "excursion": [list(e) for e in self.motion.excursion(t)],
            "status": ["%02X" % x for x in s.status[:6]] + ["%02X" % self.st6(t)],
            "queue": self.motion.queued(t),
            "index": s.index,
            "checksums": s.checksums,
            "outputs": "%02X" % s.outputs,
            "inputs": {str(k): "%02X" % v for k, v in s.inputs.items()},
            "spindle": s.spindle,
            "modal": {"V": m.V, "A": m.A, "B": m.B, "$": m.dollar, "T": m.T,
                      "VK": m.VK, "VL": list(m.VL), "XM": s.xm},
            "microstep": s.microstep if self.profile.microstep else None,
            "mpg": s.mpg or None,
            "kept": s.saved is not None,
            "packet_open": s.packet is not None,
            "eeprom": str(self.eeprom.path) if self.eeprom.path else None,
            "mutant": self.mutant.name,
        }
