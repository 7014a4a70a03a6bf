#!/usr/bin/env python3
"""GVE54 simulator (Gravos CNC motion controller, program Ip54v3 of 21.12.2007).

Written from the vendor's instruction set (given/GVE54-manual.txt) alone.  Every
place where the manual had to be interpreted is numbered [Rn] and explained in
READINGS.md.

    python3 sim.py --cosim [--model GVE54] [--address N]

speaks the co-simulation protocol of given/cosim.md (virtual time) with the test
rig of given/rig.md on standard input/output.

Structure:
  Vector, Profile, plan()  -- one queued line vector and its velocity profile
  Unit                     -- the controller: receiver, watchdog, command
                              interpreter, queue/interpolator, status, transmitter
  Cosim                    -- the line protocol: clock, byte queues, rig commands
"""
import argparse
import copy
import json
import math
import re
import sys
from collections import deque

NS = 1_000_000_000
RESTART_NS = 2 * NS              # "cca po 2s" after power-on or J          [R30]
WATCHDOG_NS = 100_000_000        # frame must be complete 100 ms after '!'  [R5]
QUEUE_SIZE = 96                  # "buffer na 96 CONT. vektorů"             [R14]
VERSION = "IP54 v3 21.12.2007"   # "PROGRAM: Ip54v3 z 21.12.2007"           [R27]
PROCESSOR_ID = "21120701"        # ddmmrrpp, see Q                          [R28]
MAX_FRAME = 64                   # receive buffer; longer frames -> error 4 [R4]
STEP_EPS = 1e-6                  # float tolerance when counting steps

# error codes (ODPOVĚDI): bit 3 of the answer digit is INTA
E_OK, E_FULL, E_WATCHDOG, E_UNKNOWN, E_SYNTAX, E_RANGE, E_NOGO, E_RUNNING = range(8)

# ST6 bits
B_STOP, B_FREE, B_INTCOM, B_FULL, B_RUN, B_INTA = 0x01, 0x02, 0x10, 0x20, 0x40, 0x80

MICRO = {'2': 8, '4': 4, '8': 2, 'F': 1}   # M mode -> P (1/16 steps per pulse)

DEC = re.compile(r'-?[0-9]+\Z')
HEX = re.compile(r'[0-9A-Fa-f]+\Z')


class CmdError(Exception):
    def __init__(self, code):
        super().__init__(code)
        self.code = code


# --------------------------------------------------------------------------
# motion
# --------------------------------------------------------------------------

class Vector:
    """One L or C vector as held in the queue.  Pulses are motor pulses of the
    microstep mode in force when the vector was accepted; P converts them to
    the 1/16 counter [R16]."""

    def __init__(self, kind, d, P, V, A, B, short, T):
        self.kind = kind          # 'L' or 'C'
        self.d = d                # pulses per axis (signed)
        self.P = P                # 1/16 steps per pulse
        self.V = V                # pulses/s (major axis)            [R10]
        self.A = A                # pulses/s^2
        self.B = B                # pulses/s
        self.short = short        # major < $ at acceptance          [R13]
        self.T = T                # dwell before it, ms (L only)     [R11]
        self.n = max(abs(c) for c in d)
        self.done = 0             # major-axis pulses already made
        self.started = False

    def vc(self):
        """Speed the vector tries to reach: V, or only B for a short one."""
        return min(self.V, self.B) if self.short else self.V

    def offset(self, k):
        """Counter units moved after k major-axis pulses (Bresenham-like
        rounding of the minor axes, half up) [R12]."""
        n = self.n
        if n == 0:
            return [0, 0, 0]
        out = []
        for c in self.d:
            m = (2 * k * abs(c) + n) // (2 * n)
            out.append(m * self.P if c >= 0 else -m * self.P)
        return out


class Profile:
    """Continuous major-axis motion of the current vector from instant t0:
    phases of constant acceleration; a pulse is made when the position
    crosses the next whole number [R12]."""

    def __init__(self, t0, x0, phases, x_end, v_end, reaches_end):
        self.t0, self.x0, self.phases = t0, x0, phases
        self.x_end, self.v_end, self.reaches_end = x_end, v_end, reaches_end
        dur = sum(p[0] for p in phases)
        self.end_ns = t0 + int(round(dur * NS))

    def at(self, t):
        """(x, v) at the instant t."""
        if t >= self.end_ns:
            return self.x_end, self.v_end
        tau = (t - self.t0) / NS
        x = self.x0
        for dur, v, acc in self.phases:
            if tau <= dur:
                return min(self.x_end, x + v * tau + 0.5 * acc * tau * tau), v + acc * tau
            x += v * dur + 0.5 * acc * dur * dur
            tau -= dur
        return self.x_end, self.v_end


def plan(x0, v0, n, vc, a, ve, stopping):
    """Phases from position x0 at speed v0 to the end n of a vector, cruising
    at vc, ending at ve, accelerating/braking at a.  With stopping: brake at
    a at once, to rest or to the end of the vector (the ramp then goes on in
    the next one).  Returns (phases, x_end, v_end, reaches_end)."""
    R = n - x0
    if stopping:
        d = v0 * v0 / (2 * a)
        if d < R - 1e-9:
            return [(v0 / a, v0, -a)], x0 + d, 0.0, False
        v1 = math.sqrt(max(0.0, v0 * v0 - 2 * a * R))
        return [((v0 - v1) / a, v0, -a)], n, v1, True
    if R <= 1e-12:
        return [], n, min(v0, ve), True
    if v0 <= vc:
        vp2 = (2 * a * R + v0 * v0 + ve * ve) / 2
        if vp2 < v0 * v0:          # cannot even reach ve: brake throughout
            v1 = math.sqrt(max(0.0, v0 * v0 - 2 * a * R))
            return [((v0 - v1) / a, v0, -a)], n, v1, True
        vp = min(vc, math.sqrt(vp2))
        d1 = (vp * vp - v0 * v0) / (2 * a)
        d3 = (vp * vp - ve * ve) / (2 * a)
        d2 = max(0.0, R - d1 - d3)
        ph = []
        if vp > v0:
            ph.append(((vp - v0) / a, v0, a))
        if d2 > 0 and vp > 0:
            ph.append((d2 / vp, vp, 0.0))
        if vp > ve:
            ph.append(((vp - ve) / a, vp, -a))
        return ph, n, ve, True
    # v0 > vc (after XD/XA): brake to vc, cruise, brake to ve
    d1 = (v0 * v0 - vc * vc) / (2 * a)
    d3 = (vc * vc - ve * ve) / (2 * a)
    if d1 + d3 > R:
        v1 = math.sqrt(max(0.0, v0 * v0 - 2 * a * R))
        return [((v0 - v1) / a, v0, -a)], n, v1, True
    ph = [((v0 - vc) / a, v0, -a)]
    if R - d1 - d3 > 0:
        ph.append(((R - d1 - d3) / vc, vc, 0.0))
    if vc > ve:
        ph.append(((vc - ve) / a, vc, -a))
    return ph, n, ve, True


# --------------------------------------------------------------------------
# the unit
# --------------------------------------------------------------------------

class Unit:
    def __init__(self, address, baud):
        self.address = address
        self.addr_byte = ord(str(address))       # one ASCII digit [R3]
        self.b = round(10 * NS / baud)
        self.eeprom = [0xFF] * 256                 # [R25]
        self.inputs = [0xFF, 0xFF, 0xFF]           # rig levels
        self.switches = {}                         # no W on the GVE54 [R32]
        self.phys = [0, 0, 0]                      # where the axes are
        self.excursion = [[0, 0], [0, 0], [0, 0]]
        # transmitter
        self.tx_queue = deque()
        self.tx_end = None                          # completion of byte on the wire
        self.tx_byte = None
        self.jump_pending = False
        self.restart_until = 0         # at clock 0 the unit is ready [R38]
        self.reset(0)

    # ---------------------------------------------------------------- reset
    def reset(self, t):
        """Reset state of the manual's RESET section (power-on or J)."""
        self.stop_abruptly(t)
        self.held = deque()
        self.mstate = 'idle'          # idle | wait (dwell before an L) | moving
        self.prof = None
        self.stopping = False
        self.start_at = None
        self.last_rest = t
        self.st = [0, 0, 0, 0]        # ST0..ST3
        self.st4 = self.st5 = 0
        self.inta = self.intcom = False
        self.prev_active = 0
        self.V, self.A, self.B, self.S, self.T = 1000, 20, 50000, 512, 5   # [R11]
        self.P, self.mode, self.current = 1, 'F', 'D'
        self.outputs = 0xFF
        self.offset = list(self.phys)   # counters zeroed, axes stay
        self.index = 0
        self.last_answer = None
        self.keep = None
        self.frame = None
        self.wd_deadline = None
        self.h_pending = False

    # ------------------------------------------------------------- position
    def cur_k(self, t):
        vec = self.held[0]
        x, _ = self.prof.at(t)
        return max(self.base_k, min(vec.n, int(math.floor(x + STEP_EPS))))

    def live_phys(self, t):
        if self.mstate != 'moving':
            return list(self.phys)
        vec = self.held[0]
        k = self.cur_k(t)
        o1, o0 = vec.offset(k), vec.offset(self.base_k)
        return [p + a - b for p, a, b in zip(self.base_phys, o1, o0)]

    def counters(self, t):
        return [p - o for p, o in zip(self.live_phys(t), self.offset)]

    def note_excursion(self, ph):
        for i, p in enumerate(ph):
            self.excursion[i][0] = min(self.excursion[i][0], p)
            self.excursion[i][1] = max(self.excursion[i][1], p)

    def commit(self, t):
        """Make the current vector's pulses so far permanent."""
        if self.mstate == 'moving':
            vec = self.held[0]
            k = self.cur_k(t)
            self.phys = self.live_phys(t)
            vec.done = k
            self.base_phys, self.base_k = list(self.phys), k
            self.note_excursion(self.phys)

    def stop_abruptly(self, t):
        """Power-on / J: pulses end where they are (no ramp)."""
        if getattr(self, 'mstate', None) == 'moving':
            self.commit(t)
        self.mstate = 'idle'

    # ---------------------------------------------------------- interpolator
    def exit_speed(self):
        """Speed at the end of the current vector: B if a C follows [R13],
        limited by the V of both and so that every later vector can still
        brake to rest at the end of the queue (backward pass) [R15]."""
        h = self.held
        e = 0.0
        for i in range(len(h) - 2, -1, -1):
            cur, nxt = h[i], h[i + 1]
            cap = min(cur.B, cur.vc(), nxt.vc())
            e = min(cap, math.sqrt(e * e + 2 * nxt.A * (nxt.n - nxt.done)))
        return e

    def make_profile(self, t, x0, v0):
        vec = self.held[0]
        ph, xe, ve, reach = plan(x0, v0, vec.n, vec.vc(), vec.A,
                                 self.exit_speed(), self.stopping)
        self.prof = Profile(t, x0, ph, xe, ve, reach)

    def start_vector(self, t, v0):
        vec = self.held[0]
        vec.started = True
        self.mstate = 'moving'
        self.base_phys, self.base_k = list(self.phys), vec.done
        self.note_excursion(self.phys)
        self.make_profile(t, float(vec.done), v0)

    def try_start(self, t):
        """Start the queue from rest (not while INTA holds it) [R9][R11]."""
        if self.mstate != 'idle' or not self.held or self.inta:
            return
        vec = self.held[0]
        if vec.kind == 'L' and not vec.started:
            at = max(t, self.last_rest + vec.T * 1_000_000)
            if at > t:
                self.mstate, self.start_at = 'wait', at
                return
        self.start_vector(t, 0.0)

    def replan(self, t):
        """New C vector, X?, or a stop request: the profile from now on."""
        if self.mstate != 'moving':
            return
        x, v = self.prof.at(t)
        self.make_profile(t, x, v)

    def begin_stop(self, t):
        """Brake on the ramp (interrupt, H, SW6).  True if a ramp runs."""
        if self.mstate == 'wait':
            self.mstate = 'idle'
            return False
        if self.mstate != 'moving':
            return False
        if not self.stopping:
            self.stopping = True
            self.replan(t)
        return True

    def motion_event(self, t):
        """Profile ended at t: vector end, or rest after a stop ramp."""
        if self.mstate == 'wait':
            self.start_vector(t, 0.0)
            return
        prof = self.prof
        self.commit(t)
        if prof.reaches_end:
            self.held.popleft()
            if self.held and (not self.stopping or prof.v_end > 1e-9):
                self.start_vector(t, prof.v_end)
                return
        # at rest (commit() has booked the pulses made, vec.done included)
        self.mstate, self.prof = 'idle', None
        self.last_rest = t
        if self.stopping:
            self.stopping = False
            if self.h_pending:
                self.h_pending = False
                self.last_answer = self.code(E_OK)
                self.answer(t, self.last_answer)

    # -------------------------------------------------------------- status
    def st6(self):
        v = 0
        if self.stopping:
            v |= B_STOP
        if self.intcom:
            v |= B_INTCOM
        if self.held:
            v |= B_RUN
        if self.inta:
            v |= B_INTA
        return v

    def active(self):
        """Enabled inputs at their active level [R21]."""
        a1 = ~(self.inputs[1] ^ self.st[2]) & 0xFF & self.st[0]
        a2 = ~(self.inputs[2] ^ self.st[3]) & 0xFF & self.st[1]
        return a1 | (a2 << 8)

    def check_interrupts(self, t):
        if t < self.restart_until:
            return
        a = self.active()
        new = a & ~self.prev_active
        self.prev_active = a
        if new:
            self.st4 |= new & 0xFF
            self.st5 |= new >> 8
            self.inta = True
            self.begin_stop(t)

    def busy(self):
        """'za chodu': the interpolator is moving (or about to) [R20]."""
        return self.mstate != 'idle'

    # ------------------------------------------------------------ receiver
    def receive(self, t, byte):
        """One byte complete at the receiver: '!' address command params CR [R1]."""
        if t < self.restart_until:
            return                          # deaf while restarting
        if byte == 0x21:                    # '!' starts a frame [R4]
            self.frame = bytearray()
            self.wd_deadline = t + WATCHDOG_NS
            return
        if self.frame is None:
            return                          # noise between frames
        if byte == 0x0D:
            frame, self.frame, self.wd_deadline = self.frame, None, None
            self.on_frame(t, bytes(frame))
            return
        self.frame.append(byte)

    def watchdog(self, t):
        frame, self.frame, self.wd_deadline = self.frame, None, None
        if frame and frame[0] == self.addr_byte and not self.h_pending:
            self.answer(t, self.code(E_WATCHDOG))       # [R5]

    def on_frame(self, t, frame):
        if not frame or frame[0] != self.addr_byte:
            return                          # another unit's frame
        if self.h_pending:
            return                          # still owes the H answer [R8]
        text = frame[1:].decode('latin-1')
        if text not in ('@', '>'):
            self.index = (self.index + 1) & 0xFF          # [R23]
        if len(frame) > MAX_FRAME:
            ans = self.code(E_SYNTAX)
        else:
            try:
                ans = self.execute(t, text)
            except CmdError as e:
                ans = self.code(e.code)
        if ans is None:
            return                          # H waiting for rest
        if text != '>':
            self.last_answer = ans
        self.answer(t, ans)

    # --------------------------------------------------------- transmitter
    def answer(self, t, text):
        """Hand an answer to the UART at t: no processing delay, its first
        byte completes one byte time later [R37]."""
        self.tx_queue.extend(text.encode('latin-1') + b'\r')
        if self.tx_end is None:
            self.tx_byte = self.tx_queue.popleft()
            self.tx_end = t + self.b

    def tx_complete(self, t):
        byte = self.tx_byte
        if self.tx_queue:
            self.tx_byte = self.tx_queue.popleft()
            self.tx_end = t + self.b
        else:
            self.tx_byte = self.tx_end = None
            if self.jump_pending:           # J: jump once answered [R29]
                self.jump_pending = False
                self.reset(t)
                self.restart_until = t + RESTART_NS
        return byte

    # --------------------------------------------------------------- events
    def motion_due(self):
        if self.mstate == 'wait':
            return self.start_at
        if self.mstate == 'moving':
            return self.prof.end_ns
        return None

    def next_event(self):
        c = [x for x in (self.motion_due(), self.wd_deadline, self.tx_end,
                         self.restart_until if self.restart_until > 0 else None)
             if x is not None]
        return min(c) if c else None

    def step(self, t):
        """Run the unit's own events due at t.  Returns (bytes completed to
        the host, whether something visible happened)."""
        out, visible = [], False
        for _ in range(10000):
            if self.restart_until and self.restart_until <= t:
                self.restart_until = 0
                visible = True
                continue
            m = self.motion_due()
            if m is not None and m <= t:
                if self.mstate == 'moving':
                    visible = True       # a vector or a stop ramp ends
                self.motion_event(t)
                continue
            if self.wd_deadline is not None and self.wd_deadline <= t:
                self.watchdog(t)
                visible = True
                continue
            if self.tx_end is not None and self.tx_end <= t:
                out.append(self.tx_complete(t))
                visible = True
                if out[-1] == 0x0D:
                    break               # the caller may have to stop here
                continue
            break
        return out, visible

    # --------------------------------------------------------- rig actions
    def power_on(self, t):
        # [R29][R30][R36]
        """Rig power-on: reset state, deaf 2 s; an answer already on its way
        completes, one due later (H) is never sent."""
        self.jump_pending = False
        self.reset(t)
        self.restart_until = t + RESTART_NS

    def set_input(self, t, port, value):
        self.inputs[port] = value
        self.check_interrupts(t)

    def state(self, t):
        ph = self.live_phys(t)
        self.note_excursion(ph)
        return {
            "profile": "GVE54",
            "address": self.address,
            "position": self.counters(t),
            "physical": ph,
            "excursion": [list(e) for e in self.excursion],
            "status": ["%02X" % v for v in self.st + [self.st4, self.st5, self.st6()]],
            "outputs": "%02X" % self.outputs,
            "spindle": 0,
            "rate_position": None,
            "rate": None,
            "inputs": {str(i): "%02X" % v for i, v in enumerate(self.inputs)},
            "time_ns": t,
            "queue": len(self.held),
            "index": self.index,
            "checksums": False,
            "modal": {"V": self.V, "A": self.A, "B": self.B, "$": self.S, "T": self.T},
            "microstep": self.mode,
            "current": self.current,
            "kept": self.keep is not None,
            "packet_open": False,
            "restarting": self.restart_until > t,
            "motion": self.mstate,
        }

    # ------------------------------------------------------------- commands
    def code(self, err, *params):
        """Answer: hex digit INTA<<3 | error, then the parameters [R2][R40]."""
        s = "%X" % ((8 if self.inta else 0) | err)
        return ",".join([s] + [str(p) for p in params])

    @staticmethod
    def dec(text, count):
        parts = text.split(',')
        if len(parts) != count or not all(DEC.match(p) for p in parts):
            raise CmdError(E_SYNTAX)
        return [int(p) for p in parts]

    @staticmethod
    def hexv(text):
        if not HEX.match(text):
            raise CmdError(E_SYNTAX)
        v = int(text, 16)
        if v > 0xFF:
            raise CmdError(E_RANGE)
        return v

    @staticmethod
    def rng(v, lo, hi):
        if not lo <= v <= hi:
            raise CmdError(E_RANGE)
        return v

    @staticmethod
    def bare(rest):
        if rest:
            raise CmdError(E_SYNTAX)

    def execute(self, t, s):
        """Run one command; the answer text, or None when it is deferred (H)."""
        if not s:
            raise CmdError(E_UNKNOWN)
        c, rest = s[0], s[1:]
        if c in 'LC':
            return self.cmd_vector(t, c, rest)
        if c in 'TVB$A':
            lim = {'T': (1, 24), 'V': (40, 50000), 'B': (40, 50000),
                   '$': (1, 65535), 'A': (1, 255)}[c]                 # [R17]
            v = self.rng(self.dec(rest, 1)[0], *lim)
            setattr(self, {'T': 'T', 'V': 'V', 'B': 'B', '$': 'S', 'A': 'A'}[c], v)
            return self.code(E_OK)
        if c == 'K':
            self.bare(rest)
            if self.busy():
                raise CmdError(E_RUNNING)
            self.keep = (copy.deepcopy(self.held), self.st4, self.st5,
                         self.inta, self.intcom)
            self.held = deque()
            self.st4 = self.st5 = 0
            self.inta = self.intcom = False
            return self.code(E_OK)
        if c == 'R':
            self.bare(rest)
            if self.busy():
                raise CmdError(E_RUNNING)
            if self.keep is not None:                                    # [R19]
                held, self.st4, self.st5, self.inta, self.intcom = self.keep
                self.held, self.keep = deque(held), None
                self.try_start(t)
            return self.code(E_OK)
        if c == 'H':                                                      # [R8][R39]
            self.bare(rest)
            self.inta = self.intcom = True
            if self.begin_stop(t) or self.stopping:
                self.h_pending = True                                    # [R8]
                return None
            return self.code(E_OK)
        if c == 'D':                                                      # [R26]
            self.bare(rest)
            if self.busy():
                raise CmdError(E_RUNNING)
            self.held = deque()
            self.st4 = self.st5 = 0
            self.inta = self.intcom = False
            return self.code(E_OK)
        if c == 'X':
            if rest not in ('A', 'U', 'D'):
                raise CmdError(E_UNKNOWN if len(rest) < 1 or rest[0] not in 'AUD'
                               else E_SYNTAX)
            for v in self.held:                                           # [R18]
                if rest == 'A':
                    v.V, v.A = self.V, self.A * 1000
                elif rest == 'U':
                    v.V = min(50000, v.V + v.V // 16)
                else:
                    v.V = max(40, v.V - v.V // 16)
            if not self.stopping:
                self.replan(t)
            return self.code(E_OK)
        if c == 'G':
            self.bare(rest)
            if not self.inta:
                raise CmdError(E_NOGO)                                    # [R9]
            if self.stopping:
                raise CmdError(E_RUNNING)
            self.inta = self.intcom = False
            self.st4 = self.st5 = 0
            if not self.held:
                raise CmdError(E_NOGO)
            self.try_start(t)
            return self.code(E_OK)
        if c == 'P':                                                      # [R33]
            if rest not in ('', 'F'):
                raise CmdError(E_SYNTAX)
            pos = self.counters(t)
            return self.code(E_OK, *(pos[:2] if rest == '' else pos))
        if c == 'N':
            self.bare(rest)
            if self.held:
                raise CmdError(E_RUNNING)     # "pri RUN=1"
            self.offset = self.live_phys(t)
            return self.code(E_OK)
        if c == 'E':
            if rest[:1] == 'R':
                return self.code(E_OK, "%02X" % self.eeprom[self.hexv(rest[1:])])
            if rest[:1] == 'W':
                parts = rest[1:].split(',')
                if len(parts) != 2:
                    raise CmdError(E_SYNTAX)
                a, v = self.hexv(parts[0]), self.hexv(parts[1])
                self.eeprom[a] = v
                return self.code(E_OK)
            raise CmdError(E_UNKNOWN)
        if c == 'M':
            if len(rest) != 1:
                raise CmdError(E_SYNTAX)
            if rest not in 'UD248F':
                raise CmdError(E_RANGE)
            if self.busy():
                raise CmdError(E_RUNNING)
            if rest in 'UD':
                self.current = rest           # no observable effect [R35]
            else:
                self.mode, self.P = rest, MICRO[rest]
            return self.code(E_OK)
        if c == 'O':                                                      # [R31]
            parts = rest.split(',')
            if len(parts) != 2 or not DEC.match(parts[0]):
                raise CmdError(E_SYNTAX)
            self.rng(int(parts[0]), 0, 0)
            self.outputs = self.hexv(parts[1])
            return self.code(E_OK)
        if c == 'I':
            port = self.rng(self.dec(rest, 1)[0], 0, 2)
            return self.code(E_OK, "%02X" % self.inputs[port])
        if c == 'S':
            if rest[:1] == 'R':
                n = self.rng(self.dec(rest[1:], 1)[0], 0, 6)         # [R34]
                return self.code(E_OK, "%02X" % self.read_st(n))
            if rest[:1] == 'W':
                parts = rest[1:].split(',')
                if len(parts) != 2 or not DEC.match(parts[0]):
                    raise CmdError(E_SYNTAX)
                n = int(parts[0])
                x = self.hexv(parts[1])
                self.rng(n, 0, 6)
                self.write_st(t, n, x)
                return self.code(E_OK)
            raise CmdError(E_UNKNOWN)
        if c == 'F':
            self.bare(rest)
            full = B_FULL if len(self.held) >= QUEUE_SIZE else 0
            return self.code(E_OK, "%02X" % (self.st6() | full))
        if c == '@':
            self.bare(rest)
            return self.code(E_OK, self.index)                            # [R23]
        if c == '>':                                                      # [R24]
            self.bare(rest)
            return self.last_answer if self.last_answer is not None else self.code(E_OK)
        if c == 'J':
            self.bare(rest)
            self.jump_pending = True
            return self.code(E_OK)
        if c == '?':
            self.bare(rest)
            return self.code(E_OK, VERSION)
        if c == 'Q':
            self.bare(rest)
            return self.code(E_OK, PROCESSOR_ID)
        raise CmdError(E_UNKNOWN)

    def cmd_vector(self, t, kind, rest):
        """L and C [R6][R7]; relative pulses in the current micro-step mode."""
        d = [self.rng(v, -65535, 65535) for v in self.dec(rest, 3)]
        if kind == 'L' and self.held:
            raise CmdError(E_FULL)            # L only onto an empty queue [R6]
        if len(self.held) >= QUEUE_SIZE:
            raise CmdError(E_FULL)
        vec = Vector(kind, d, self.P, self.V, self.A * 1000, self.B,
                     max(abs(x) for x in d) < self.S, self.T)
        self.held.append(vec)
        if self.mstate == 'moving':
            if not self.stopping:
                self.replan(t)
        else:
            self.try_start(t)
        return self.code(E_OK)

    def read_st(self, n):
        if n < 4:
            return self.st[n]
        return (self.st4, self.st5, self.st6())[n - 4]

    def write_st(self, t, n, x):
        if n < 4:
            self.st[n] = x
            self.check_interrupts(t)
        elif n == 4:
            self.st4 = x
        elif n == 5:
            self.st5 = x
        else:                                                             # [R22]
            self.intcom = bool(x & B_INTCOM)
            inta = bool(x & B_INTA)
            if inta and not self.inta:
                self.inta = True
                self.begin_stop(t)
            elif not inta and self.inta and not self.stopping:
                self.inta = False
                self.try_start(t)


# --------------------------------------------------------------------------
# co-simulation protocol (given/cosim.md) and rig (given/rig.md)
# --------------------------------------------------------------------------

def number(word):
    if not word or len(word) > 20 or not all('0' <= ch <= '9' for ch in word):
        raise ValueError("bad number %r" % word)
    return int(word)


def hexbytes(word):
    if not word or len(word) % 2 or not all(ch in '0123456789abcdefABCDEF' for ch in word):
        raise ValueError("bad hex %r" % word)
    return bytes.fromhex(word)


class Cosim:
    def __init__(self, unit, baud):
        self.unit = unit
        self.now = 0
        self.b = round(10 * NS / baud)
        self.rx = deque()          # (instant, byte) on their way to the unit
        self.snap = None           # (unit, instant) kept by 'snapshot'

    def advance(self, limit, cr_stop):
        """Run the clock to limit; returns (bytes to host [(t, b)], stopped at CR)."""
        out = []
        u = self.unit
        while True:
            tu = u.next_event()
            tr = self.rx[0][0] if self.rx else None
            cand = [x for x in (tu, tr) if x is not None]
            if not cand or min(cand) > limit:
                self.now = limit
                return out, False
            t = min(cand)
            self.now = t
            if tu is not None and tu <= t:       # own events before a byte
                bs, _ = u.step(t)
                for byte in bs:
                    out.append((t, byte))
                    if byte == 0x0D and cr_stop:
                        return out, True
                continue
            _, byte = self.rx.popleft()
            u.receive(t, byte)

    def do_tx(self, data, until):
        start = self.now
        for i, byte in enumerate(data):
            self.rx.append((start + (i + 1) * self.b, byte))
        out, _ = self.advance(start + len(data) * self.b, False)
        if until is not None and not any(b == 0x0D for _, b in out):
            more, _ = self.advance(until, True)
            out += more
        return out

    def reply_rx(self, out):
        return ["rx %d %02X" % (t, b) for t, b in out] + ["now %d" % self.now]

    def next_event(self):
        clone = copy.deepcopy(self.unit)
        rx = list(self.rx)
        for _ in range(100000):
            t = clone.next_event()
            if rx and (t is None or rx[0][0] < t):
                return "next %d" % rx[0][0]
            if t is None:
                return "next none"
            _, visible = clone.step(t)
            if visible and t > self.now:
                return "next %d" % t
        return "error: cannot tell"

    def strip_address(self, words):
        if len(words) > 1 and words[-1].startswith('@'):
            if number(words[-1][1:]) != self.unit.address:
                raise ValueError("no unit at %s" % words[-1])
            return words[:-1]
        return words

    def command(self, line):
        """One command line -> list of reply lines (None: quit)."""
        words = line.split()
        if not words:
            return []
        cmd, args = words[0], words[1:]
        u = self.unit
        try:
            if cmd in ('quit', 'exit'):
                return None
            if cmd == 'tx':
                if len(args) not in (1, 2):
                    raise ValueError("tx HEX [T]")
                data = hexbytes(args[0])
                until = number(args[1]) if len(args) == 2 else None
                if until is not None and until < self.now + len(data) * self.b:
                    raise ValueError("T before the bytes' end")
                return self.reply_rx(self.do_tx(data, until))
            if cmd == 'until':
                if len(args) != 1:
                    raise ValueError("until T")
                t = number(args[0])
                if t < self.now:
                    raise ValueError("until before now")
                out, _ = self.advance(t, True)
                return self.reply_rx(out)
            if cmd == 'batch':
                if not args or len(args) % 2:
                    raise ValueError("batch D HEX [D HEX ...]")
                pairs = [(number(args[i]), hexbytes(args[i + 1]))
                         for i in range(0, len(args), 2)]
                lines = []
                for d, data in pairs:
                    end = self.now + len(data) * self.b
                    out = self.do_tx(data, end + d)
                    lines += self.reply_rx(out)
                    if not any(b == 0x0D for _, b in out):
                        break                      # batch-stops
                return lines
            if cmd == 'next':
                if args:
                    raise ValueError("next takes no argument")
                return [self.next_event()]
            if cmd == 'baud':
                if len(args) != 1:
                    raise ValueError("baud N")
                n = number(args[0])
                if n == 0:
                    raise ValueError("baud 0")
                self.b = u.b = round(10 * NS / n)
                return ["ok"]
            if cmd == 'help':
                return ["commands: tx HEX [T] | until T | next | baud N | batch D HEX ... | "
                        "in PORT HEX | switch AXIS POS|none | rate POS|none | power-on | "
                        "state | snapshot | restore | quit  [@ADDRESS]"]
            args = self.strip_address(words)[1:]
            if cmd == 'in':
                if len(args) != 2:
                    raise ValueError("in PORT XX")
                port = number(args[0])
                if port > 2 or len(args[1]) != 2:
                    raise ValueError("in PORT XX (port 0..2, two hex digits)")
                u.set_input(self.now, port, hexbytes(args[1])[0])
                return ["ok"]
            if cmd == 'switch':
                if len(args) != 2 or args[0] not in ('X', 'Y', 'Z'):
                    raise ValueError("switch X|Y|Z POS|none")
                if args[1] == 'none':
                    u.switches.pop(args[0], None)
                else:
                    p = args[1]
                    neg = p[:1] == '-'
                    v = number(p[1:] if p[:1] in '+-' else p)
                    u.switches[args[0]] = -v if neg else v
                return ["ok"]
            if cmd == 'rate':
                if args == ['none']:
                    return ["ok"]
                raise ValueError("the GVE54 manual gives no table of jumper rates")
            if cmd == 'power-on':
                if args:
                    raise ValueError("power-on takes no argument")
                u.power_on(self.now)
                self.rx = deque((t, b) for t, b in self.rx if t < self.now)
                return ["ok"]
            if cmd == 'state':
                if args:
                    raise ValueError("state takes no argument")
                return [json.dumps(u.state(self.now))]
            if cmd == 'snapshot':
                if args:
                    raise ValueError("snapshot takes no argument")
                self.snap = (copy.deepcopy(u), self.now)
                return ["ok"]
            if cmd == 'restore':
                if args:
                    raise ValueError("restore takes no argument")
                if self.snap is None:
                    raise ValueError("no snapshot taken")
                unit, t0 = self.snap
                self.unit = copy.deepcopy(unit)
                self.unit.b = self.b        # the line's rate is the line's
                # the unit has stood untouched from the snapshot's instant to now
                while True:
                    t = self.unit.next_event()
                    if t is None or t > self.now:
                        break
                    self.unit.step(t)
                return ["now %d" % self.now]
            raise ValueError("unknown command %r" % cmd)
        except ValueError as e:
            return ["error: %s" % e]


def main():
    ap = argparse.ArgumentParser(description="GVE54 simulator (virtual-time co-simulation)")
    ap.add_argument('--cosim', action='store_true',
                    help='speak the co-simulation protocol on stdin/stdout')
    ap.add_argument('--model', default='GVE54', help='only GVE54 is simulated')
    ap.add_argument('--address', type=int, default=0, help="the unit's address 0..9")
    ap.add_argument('--baud', type=int, default=115200, help='initial line rate')
    a = ap.parse_args()
    if a.model.upper() != 'GVE54':
        ap.error("only --model GVE54 is simulated")
    if not 0 <= a.address <= 9:
        ap.error("--address must be 0..9 (one ASCII digit in the frame)")
    if not a.cosim:
        ap.error("only --cosim (virtual time) is implemented; see README.md")
    sim = Cosim(Unit(a.address, a.baud), a.baud)
    out = sys.stdout
    out.write("cosim 1 batch batch-stops snapshot\n")
    out.flush()
    for raw in sys.stdin:
        line = raw.rstrip('\n').rstrip('\r')
        try:
            replies = sim.command(line)
        except Exception as e:          # never die on the suite: report, go on
            import traceback
            traceback.print_exc(file=sys.stderr)
            replies = ["error: internal error: %s" % e]
        if replies is None:
            break
        for r in replies:
            out.write(r + "\n")
        out.flush()
    return 0


if __name__ == '__main__':
    sys.exit(main())
