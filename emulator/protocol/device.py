"""The device: the machine behind the serial protocol (docs/architecture.md).

It owns the profile, the protocol state a reset restores (state.py), the stepper core,
the EEPROM, and what the test rig's hands set: the input levels (physical: a reset does
not change them, spec 10.3) and the virtual reference switches. The session (index,
history, checksum mode, packets) is not here, and neither is the command table: the
command handlers act on the device through the methods below.
"""

from __future__ import annotations

import math
import struct
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Any

from emulator.motion.factory import create
from emulator.motion.interface import Vector
from emulator.mutants import Mutant
from emulator.protocol.eeprom import Eeprom
from emulator.protocol.params import CommandError
from emulator.protocol.state import FREE, INTA, RUN, STOP, DeviceState, reset_state
from emulator.readings import NONE as NO_READINGS
from emulator.readings import Readings
from gve_fixtures.profile import Profile
from gve_fixtures.protocol import ErrorCode

MS = 1_000_000
#: the reading steps-a-period-late: how far back a step period is looked for
LATE_WINDOW = 100 * MS
#: the reading counters-a-tick-late: the tick its counters follow the axes on
TICK = MS
#: the mutant slow-rates-floored: the slowest rate its timer runs (pulses/s)
SLOWEST = 100
#: input ports read FF with nothing connected (spec 10.3)
UNCONNECTED = {0: 0xFF, 1: 0xFF, 2: 0xFF}


class Device:
    def __init__(self, profile: Profile, *, mutant: Mutant, eeprom_path: str | Path | None = None,
                 stepper: str | None = None, origin: int = 0,
                 readings: Readings = NO_READINGS) -> None:
        self.profile = profile
        self.mutant = mutant
        self.readings = readings
        shipped = profile.eeprom
        if readings.active("eeprom-erased-zero"):
            shipped = replace(shipped, erased=0x00)
        self.eeprom = Eeprom(shipped.image(), eeprom_path)
        #: the mutant eeprom-forgotten-at-restart: bytes as they were before the writes
        #: since the last restart, given back at the next
        self._unsaved: dict[int, int] = {}
        #: the last vector queued, in commanded steps (the mutant refused-vector-overwrites)
        self.last_vector: tuple[int, ...] | None = None
        #: whether the last vector accepted was a C (an L is accepted only alone)
        self.last_continuous = False
        scale = profile.position_scale if profile.microstep is not None else 1
        self.motion = create(len(profile.axes), profile.max_rate * scale, stepper=stepper,
                             deviations=mutant.deviations | readings.deviations)
        self.motion.advance(origin)
        self.inputs = dict(UNCONNECTED)
        self.switches: dict[str, int | None] = {}
        #: the rate switch's (or jumpers') position the rig set (None: never set, the
        #: unit runs at whatever rate its line runs at, as it was ordered or set up)
        self.rate_position: int | None = None
        #: the line rate read at the last power-on (None: the line's, as above)
        self.rate: int | None = None
        self._position_read: int | None = None     # the position the last power-on read
        self.state: DeviceState = self._reset_state()
        self.deaf_until = origin          # restarting (power-on, J) until then
        self._was_active = self._active()  # the reading edge-triggered-inputs: last seen
        #: work due later that answers nothing (the mutant reference-answers-early's run)
        self.due: list[tuple[int, Callable[[int], object]]] = []

    # -- power ------------------------------------------------------------------------
    def _reset_state(self) -> DeviceState:
        """Spec 9's reset state; under the reading mpg-on-when-sent the MPG mode is none
        until a `Y` is sent (its `&` of the reset inert)."""
        state = reset_state(self.profile)
        if state.mpg and self.readings.active("mpg-on-when-sent"):
            state.mpg = ""
        return state

    def reset(self, t: int) -> None:
        """Power-on or J: the reset state of spec 9, deaf for the restart. The axes stay
        where they are (the counters read 0) and so do the input levels."""
        p = self.profile
        self.state = self._reset_state()
        self.motion.clear(t)
        for axis in range(len(p.axes)):
            self.motion.set_position(axis, 0, t)
        self.motion.set_multiplier(self.state.xm, t)
        if self.mutant.active("restart-resets-inputs"):
            self.inputs = dict(UNCONNECTED)
        for address, value in sorted(self._unsaved.items()):
            self.eeprom.write(address, bytes([value]))
        self._unsaved = {}
        self._was_active = self._active()
        self.deaf_until = t + p.restart_ms * MS
        self.due = []
        if self.mutant.active("baud-read-at-restart"):
            self.read_rate()
        elif self.mutant.active("baud-range-read-at-restart"):
            self._take_rate(self._position_read)

    def read_rate(self) -> None:
        """Power-on: the rate from the switch (jumpers) and the range byte, read once
        (M114 13.3, 10.1; M54 SERIE); a unit whose switch the rig never set keeps the
        line's rate."""
        self._position_read = self.rate_position
        self._take_rate(self.rate_position)

    def _take_rate(self, position: int | None) -> None:
        """The rate the switch at ``position`` gives with the range byte as it is now."""
        choice = self.profile.baud
        if choice is None or position is None:
            self.rate = None
            return
        if choice.table_rule and self.mutant.active("baud-jumpers-ignored"):
            position = len(choice.positions) - 1
        if choice.table_rule and self.readings.active("rate-jumpers-reversed"):
            position = len(choice.positions) - 1 - position
        code = None
        if choice.range_address is not None:
            code = self.eeprom.read(choice.range_address)[0]
            if self.mutant.active("baud-range-ignored"):
                code = choice.unlisted_range
            elif code not in choice.ranges and self.readings.active("baud-unlisted-high"):
                code = min(c for c in choice.ranges if c != choice.unlisted_range)
        self.rate = choice.rate(position, code)

    def later(self, at: int, work: Callable[[int], object]) -> None:
        """Do ``work(at)`` at the instant ``at``, answering nothing."""
        self.due.append((at, work))

    def next_due(self) -> int | None:
        return min((at for at, _ in self.due), default=None)

    def run_due(self, t: int) -> None:
        """The work due by ``t``, each at its own instant."""
        now = [d for d in self.due if d[0] <= t]
        self.due = [d for d in self.due if d[0] > t]
        for at, work in sorted(now, key=lambda d: d[0]):
            work(at)

    # -- derived state ----------------------------------------------------------------
    def factor(self) -> int:
        """Counter units per commanded step (GVE54 micro-stepping, spec 10.7)."""
        ms = self.profile.microstep
        if ms is None:
            return 1
        mode = self.state.microstep
        if self.mutant.active("microstep-modes-swapped"):
            mode = {"2": "8", "8": "2"}.get(mode, mode)
        return ms.factors[mode]

    def mpg_active(self) -> bool:
        """The GVE114's MPG holds the axes (RUN = 1): on, and allowed by EEPROM 06."""
        mpg = self.profile.mpg
        if mpg is None or self.state.mpg not in ("+", "&"):
            return False
        value = self.eeprom.read(mpg.enable_address)[0]
        if value & 0x80 and self.mutant.active("mpg-enable-high-values-ignored"):
            return False
        return value in mpg.enabling_values and self.mpg_parameters_in_range()

    def mpg_parameters_in_range(self) -> bool:
        """Whether the MPG's parameters allow it under the readings taken (always, under
        none). mpg-needs-parameters: M114 12.4-12.6, "Pokud je hodnota některého
        parametru mimo rozsah, není možné MPG použít" (with any of them out of range the
        MPG cannot be used): the limits 0..10000, steps per mm 1..10000, the acceleration
        1..10000 and a positive maximum speed, float32 little-endian each (an erased FF
        FF FF FF is no number). mpg-needs-every-parameter: that sentence read for every
        parameter of chapter 12 with a range, the delay (12.7, 1..2000) and the default
        spindle speed (12.8, 1..1000, uint32 each) too."""
        every = self.readings.active("mpg-needs-every-parameter")
        if not every and not self.readings.active("mpg-needs-parameters"):
            return True
        floats = [(0x10 + 4 * i, 0.0, 1e4) for i in range(8)] \
            + [(0x30 + 4 * i, 1.0, 1e4) for i in range(4)] \
            + [(0x40, 1.0, 1e4), (0x44, 1e-9, math.inf)]
        uints = [(0x48, 1, 2000), (0x4C, 1, 1000)] if every else []
        for fmt, ranges in (("<f", floats), ("<I", uints)):
            for address, lo, hi in ranges:
                value = struct.unpack(fmt, self.eeprom.read(address, 4))[0]
                if not lo <= value <= hi:          # NaN compares false
                    return False
        return True

    def st6(self, t: int) -> int:
        flags = self.motion.flags(t)
        value = self.state.status[6] & ~(RUN | STOP)
        if flags.busy or self.mpg_active() or self.state.reference_until > t \
                or self.state.dwell_until > t:
            value |= RUN
        if flags.stopping:
            value |= STOP
        return value

    def moving(self, t: int) -> bool:
        """Executing, braking or dwelling, a reference run, or the MPG (spec 5)."""
        mpg = self.mpg_active() and not self.mutant.active("mpg-not-moving")
        return (self.motion.flags(t).moving or self.state.reference_until > t or mpg
                or self.state.dwell_until > t)

    def refuse_while_moving(self, t: int) -> None:
        if self.moving(t):
            raise CommandError(ErrorCode.BUSY, "not possible while moving")

    def refuse_while_running(self, t: int) -> None:
        if self.st6(t) & RUN:
            raise CommandError(ErrorCode.BUSY, "not possible while RUN = 1")

    def refuse_restore(self, t: int) -> None:
        """R: not while moving; the reading restore-refused-while-run: whenever RUN = 1,
        also while halted vectors hold it."""
        if self.readings.active("restore-refused-while-run"):
            self.refuse_while_running(t)
        self.refuse_while_moving(t)

    def refuse_vectors_to_mpg(self) -> None:
        if self.mpg_active():
            raise CommandError(ErrorCode.BUSY, "the MPG holds the axes")

    def capacity(self) -> int:
        """The queue's capacity now: one vector after K on GVE84/GVE114 (spec 10.5)."""
        if self.state.kept_single and not self.mutant.active("flags-ignore-keep-capacity"):
            return 1
        return self.profile.buffer

    def positions(self, t: int) -> tuple[int, ...]:
        """The counters as P and PF report them."""
        here = self.motion.position(t)
        if self.mutant.active("position-ignores-microstep"):
            f = self.factor()
            return tuple(int(x / f) for x in here)
        if self.mutant.active("narrow-counters"):
            return tuple((x + (1 << 23)) % (1 << 24) - (1 << 23) for x in here)
        if self.readings.active("steps-a-period-late"):
            return self._a_period_late(here, t)
        if self.readings.active("counters-a-tick-late") and self.motion.flags(t).moving:
            return self._a_tick_late(here, t)
        return here

    def _a_tick_late(self, here: tuple[int, ...], t: int) -> tuple[int, ...]:
        """The reading counters-a-tick-late: counted on a 1 ms tick of the unit's own,
        the counters show where the axes were a tick ago (the pulses since taken back)."""
        times, masks = self.motion.pulses(max(0, t - TICK + 1), t + 1)
        out = list(here)
        for mask in (int(m) for m in masks[:len(times)]):
            for i in range(len(out)):
                if (mask >> i) & 1:
                    out[i] -= -1 if (mask >> (4 + i)) & 1 else 1
        return tuple(out)

    def _a_period_late(self, here: tuple[int, ...], t: int) -> tuple[int, ...]:
        """The reading steps-a-period-late: a counter shows a step one step period after
        the instant our arithmetic places it (a unit that places its steps on a
        continuous trapezoid and rounds the counters down): while the axes move the
        last pulse is not counted yet, so each axis reads at most one step behind; a
        vector that has ended shows its end (the unit is idle only once it is there)."""
        if not self.motion.flags(t).moving:
            return here
        times, masks = self.motion.pulses(max(0, t - LATE_WINDOW), t + 1)
        if not len(times):
            return here
        last = int(times[-1])
        period = last - int(times[-2]) if len(times) > 1 else LATE_WINDOW
        if t - last >= period:
            return here
        mask = int(masks[-1])
        return tuple(x - (((mask >> i) & 1) * (-1 if (mask >> (4 + i)) & 1 else 1))
                     for i, x in enumerate(here))

    def seen_at_rest(self, rest: int) -> int:
        """When the unit sees its motion at rest: at ``rest``; under the reading
        steps-a-period-late one step period (the last) after it."""
        if not self.readings.active("steps-a-period-late"):
            return rest
        times, _ = self.motion.pulses(max(0, rest - LATE_WINDOW), rest + 1)
        if len(times) < 2:
            return rest
        return rest + int(times[-1]) - int(times[-2])

    # -- vectors ------------------------------------------------------------------------
    def push(self, steps: tuple[int, ...], continuous: bool, t: int) -> None:
        """Accept a vector with the modal parameters it captures (spec 10.1)."""
        m, p, act = self.state.modal, self.profile, self.mutant.active
        mr, f = p.max_rate, self.factor()
        v = p.reset.V if act("velocity-ignored") else m.V
        if act("override-late"):                  # XM captured instead of an override
            v = v * self.state.xm // 100
        accel = p.reset.A if act("accel-ignored") else m.A
        rate_f = 1 if act("microstep-rates-unscaled") else f
        limits = (mr,) * len(m.VL) if act("axis-limit-ignored") else m.VL
        brake = m.B
        if act("slow-rates-floored"):
            v, brake, limits = max(v, SLOWEST), max(brake, SLOWEST), [max(x, SLOWEST)
                                                                      for x in limits]
        step_f = 1 if continuous and act("microstep-continuous-unscaled") else f
        if act("a-axis-alone-ignored") and len(steps) == 4 and not any(steps[:3]):
            steps = (0, 0, 0, 0)
        self.last_vector = steps
        self.last_continuous = continuous
        accel *= 1000 * f
        path2 = sum(s * s for s in steps[:3])
        along = m.VK and not act("path-speed-ignored")
        if along and path2 and self.readings.active("accel-along-path"):
            # A along |d| as V is: the dominant axis accelerates at A·n/|d|
            accel = max(1, math.isqrt((accel * max(map(abs, steps))) ** 2 // path2))
        self.motion.push(Vector(
            steps=tuple(s * step_f for s in steps), continuous=continuous,
            velocity=min(v, mr) * rate_f, accel=accel,
            brake=min(brake, mr) * rate_f,
            short=0 if act("short-vector-ignored") else m.dollar * f,
            dwell=0 if act("dwell-ignored") else m.T * MS,
            path_speed=along,
            axis_limits=tuple(min(x, mr) * f for x in limits)), t)

    def exchange_velocity(self, t: int) -> None:
        """XA: the queue takes the modal V (the GVE54 also the modal A)."""
        if self.mutant.active("xa-ignored"):
            return
        p, f = self.profile, self.factor()
        v = p.reset.V if self.mutant.active("velocity-ignored") else self.state.modal.V
        if self.mutant.active("slow-rates-floored"):
            v = max(v, SLOWEST)
        accel = self.state.modal.A * 1000 * f if p.microstep is not None else None
        self.motion.set_velocity(min(v, p.max_rate) * f, t, accel)

    def scale_velocity(self, num: int, den: int, t: int) -> None:
        """XU / XD: the queue's speeds (the GVE54 also its accelerations) times num/den."""
        if self.mutant.active("xu-xd-swapped"):
            num = 2 * den - num                   # 17/16 <-> 15/16
        self.motion.scale_velocity(num, den, t, accel=self.profile.microstep is not None)

    def override(self, percent: int, t: int) -> None:
        """XM: an override of every vector, held and later ones (spec 10 XM)."""
        self.state.xm = percent
        if self.mutant.active("override-rewrites-velocity"):
            r, modal = self.profile.ranges["V"], self.state.modal
            modal.V = max(r.lo, min(r.hi, modal.V * percent // 100))
        if not self.mutant.active("override-late"):
            self.motion.set_multiplier(percent, t)

    # -- interrupts (spec 10.3) ---------------------------------------------------------
    def _active(self) -> tuple[int, int]:
        """The inputs that are active now (level equals polarity), per word."""
        s, i = self.state.status, self.inputs
        return ~(i[1] ^ s[2]) & 0xFF, ~(i[2] ^ s[3]) & 0xFF

    def _hits(self) -> tuple[int, int]:
        """The enabled inputs that are active now, per word; with the reading
        edge-triggered-inputs only those that became active since last looked at."""
        s, p = self.state.status, self.profile
        active1, active2 = self._active()
        if self.readings.active("edge-triggered-inputs"):
            was1, was2 = self._was_active
            self._was_active = (active1, active2)
            active1, active2 = active1 & ~was1, active2 & ~was2
        return s[0] & active1 & p.low_mask, s[1] & active2 & p.high_mask

    def check_inputs(self, t: int) -> None:
        """Level-triggered: an enabled active input sets its cause bit and INTA (and
        stops the motion on a ramp) whenever it is looked at."""
        hit1, hit2 = self._hits()
        if not (hit1 or hit2) or self.mutant.active("interrupt-ignored"):
            return
        s, act = self.state.status, self.mutant.active
        if act("cause-lowest-only"):               # the lowest of the two words' 16 bits
            both = hit1 | hit2 << 8
            hit1, hit2 = both & -both & 0xFF, (both & -both) >> 8
        elif act("cause-includes-disabled"):       # every active input, enabled or not
            active1, active2 = self._active()
            hit1, hit2 = active1 & self.profile.low_mask, active2 & self.profile.high_mask
        if not (self.state.inta and self.readings.active("cause-first-only")):
            s[4] |= hit1
            s[5] |= hit2
        inta = self.state.inta
        self.stop(t)
        if not inta and act("input-stop-drops-queue"):
            self.later(self.motion.halt(t), self.motion.clear)

    def after_clearing(self, t: int) -> None:
        """D, K, R cleared the cause bits or INTA: an input still active sets them again."""
        if not self.mutant.active("inputs-forgotten-after-delete"):
            self.check_inputs(t)

    def stop(self, t: int) -> None:
        """INTA set by an event: a stop on the ramp; later vectors wait for G."""
        if not self.state.inta:
            self.state.status[6] |= INTA
            self.motion.halt(t)

    def set_input(self, port: int, value: int, t: int) -> None:
        self.inputs[port] = value & 0xFF
        self.check_inputs(t)

    def write_status(self, n: int, value: int, t: int) -> None:
        """SW: ST0..ST5 store every bit; ST6 acts like the events its bits stand for."""
        s = self.state
        if n < 6:
            if self.mutant.active("status-word-masked"):
                value &= self.profile.low_mask if n % 2 == 0 else self.profile.high_mask
            s.status[n] = value
        elif self.mutant.active("sw6-inert"):
            s.status[6] = value & ~(RUN | STOP)
        else:
            was = s.inta
            if value & STOP and self.readings.active("sw6-stop-request"):
                value |= INTA                     # the stop request, accepted at once
            # RUN, STOP and FREE describe the stepper: writing them changes nothing
            s.status[6] = value & ~(RUN | STOP | FREE)
            if s.inta and not was:
                self.motion.halt(t)               # a stop ramp; no cause bit
            elif was and not s.inta:
                self.motion.resume(t)             # like G, but ST4/ST5 stay
        self.check_inputs(t)

    # -- the reference run ------------------------------------------------------------------
    def reference_switch(self, axis: str, here: int) -> tuple[int, bool] | None:
        """The axis's reference switch for W (spec 10 W [D]): (physical position, whether
        it releases when the axis backs off). A virtual switch placed by the rig releases
        one step back; the axis's reference input, when it is active now, is a level the
        rig holds: it is here and stays active however the axis moves."""
        if self.switches.get(axis) is not None:
            return self.switches[axis], True
        bit = self.profile.reference_inputs.get(axis)
        if bit is not None:
            level = (self.inputs[1] >> bit) & 1
            if level == (self.state.status[2] >> bit) & 1:
                return here, False
        return None

    # -- EEPROM -----------------------------------------------------------------------------
    def eeprom_cell(self, address: int) -> int:
        """The byte ER and EW reach at ``address``: every one of the 256."""
        return address & 0x7F if self.mutant.active("eeprom-7-bit-address") else address

    def write_eeprom(self, address: int, data: bytes, t: int) -> None:
        if not self.readings.active("eeprom-write-while-moving"):
            self.refuse_while_moving(t)
        if self.mutant.active("eeprom-forgotten-at-restart"):
            for i in range(len(data)):
                self._unsaved.setdefault(address + i, self.eeprom.read(address + i)[0])
        if not self.mutant.active("eeprom-write-lost"):
            self.eeprom.write(address, data)

    # -- the rig's view ---------------------------------------------------------------------
    def snapshot(self, t: int) -> dict[str, Any]:
        s, m = self.state, self.state.modal
        return {
            "position": list(self.motion.position(t)),
            "physical": list(self.motion.physical(t)),
            "excursion": [list(e) for e in self.motion.excursion(t)],
            "status": ["%02X" % x for x in s.status[:6]] + ["%02X" % self.st6(t)],
            "queue": self.motion.queued(t),
            "outputs": "%02X" % s.outputs,
            "inputs": {str(k): "%02X" % v for k, v in self.inputs.items()},
            "spindle": s.spindle,
            "modal": {"V": m.V, "A": m.A, "B": m.B, "$": m.dollar, "T": m.T,
                      "VK": m.VK, "VL": list(m.VL), "XM": s.xm},
            "microstep": s.microstep if self.profile.microstep else None,
            "mpg": s.mpg or None,
            "kept": s.saved is not None,
            "eeprom": str(self.eeprom.path) if self.eeprom.path else None,
            "rate_position": self.rate_position,
            "rate": self.rate,
        }
