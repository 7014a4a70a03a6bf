#!/usr/bin/env python3
"""GVE114 hardware interpolator simulator (clone), written from the vendor manual alone.

`python3 sim.py --cosim [--model GVE114-500] [--eeprom FILE]` speaks the co-simulation
protocol of cosim.md (virtual time) with the test rig of rig.md on the same channel.
Choices where the manual is silent or ambiguous are cited as [Rnn]; see READINGS.md.
"""
import argparse
import json
import math
import re
import struct
import sys

MODELS = {  # profile name -> interpolation rate (pulses/s)   [R1]
    'GVE114-500': 500000,
    'GVE114-200': 200000,
    'GVE114-125': 125000,
    'GVE114-50': 50000,
}
NEVER = 1 << 62
RESTART_NS = 2_000_000_000      # "cca po 2s" (13.5); rig.md: restart_ms 2 s   [R40]
WATCHDOG_NS = 100_000_000       # frame must be complete within 100 ms of its '!'  [R5]
QMAX = 2048                     # "buffer na 2048 CONT. vektoru" incl. the one executing [R14]
MAXFRAME = 120                  # longer frames are a syntax error  [R7]
LOOKAHEAD = 32                  # brake-map look-ahead horizon  [R19]
NAXES = 4
CR = 0x0D

# 10.1 COM SPEED table: positions 0..3 = sw1/sw2 OFF/OFF, OFF/ON, ON/OFF, ON/ON   [R41]
RATES_01 = [921600, 460800, 230400, 115200]
RATES_FF = [19200, 38400, 57600, 115200]

RE_INT = re.compile(r'^[+-]?[0-9]+$')
RE_UINT = re.compile(r'^[0-9]+$')
RE_HEX = re.compile(r'^[0-9A-Fa-f]{1,2}$')
RE_FLOAT = re.compile(r'^[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?$')


class CmdError(Exception):
    def __init__(self, code):
        super().__init__(code)
        self.code = code


def pint(s, lo, hi):
    """Signed decimal parameter: 4 if malformed, 5 if out of range.  [R59]"""
    if not RE_INT.match(s or ''):
        raise CmdError(4)
    v = int(s)
    if v < lo or v > hi:
        raise CmdError(5)
    return v


def pints(parts, lo, hi):
    """Several decimal parameters: any syntax error (4) before any range error (5)."""
    for x in parts:
        if not RE_INT.match(x or ''):
            raise CmdError(4)
    return [pint(x, lo, hi) for x in parts]


def phex(s, lo=0, hi=255):
    if not RE_HEX.match(s or ''):
        raise CmdError(4)
    v = int(s, 16)
    if v < lo or v > hi:
        raise CmdError(5)
    return v


def params(s, nmin, nmax):
    parts = s.split(',') if s != '' else []
    if len(parts) < nmin or len(parts) > nmax:
        raise CmdError(4)
    return parts


def fmt_float(f):  # [R33]
    if math.isnan(f):
        return 'nan'
    if math.isinf(f):
        return 'inf' if f > 0 else '-inf'
    return '%.7g' % f


class Vec:
    __slots__ = ('d', 'kind', 'speed', 'acc', 'brake', 'short', 'dwell', 'vk', 'vl', 's', 'Lm')

    def __init__(self, d, kind, m):
        self.d = d
        self.kind = kind
        self.speed = m['V'] * m['XM'] / 100.0
        self.acc = m['A']
        self.brake = m['B']
        self.short = m['$']
        self.dwell = m['T']
        self.vk = m['VK']
        self.vl = list(m['VL'])
        self.s = 0.0
        self.Lm = max(abs(x) for x in d)

    def copy(self):
        v = Vec.__new__(Vec)
        for k in Vec.__slots__:
            val = getattr(self, k)
            setattr(v, k, list(val) if isinstance(val, list) else val)
        return v


def steps_at(vec, s):
    """Steps done on each axis at master progress s (Bresenham-like floor).  [R17]"""
    if vec.Lm == 0:
        return [0] * NAXES
    out = []
    for di in vec.d:
        if di == 0:
            out.append(0)
        else:
            k = int(math.floor(s * abs(di) / vec.Lm + 1e-6))
            k = min(k, abs(di))
            out.append(k if di > 0 else -k)
    return out


class Seg:
    """One planned piece of motion of the current vector from (t0, s0, v0)."""
    __slots__ = ('vec', 't0', 's0', 'v0', 'phases', 't_end', 's_end', 'v_end', 'stop', 'halting')


def plan(vm, a, D, v0, ve_target, halting):
    """Trapezoid from the current state. Returns (phases, s_travel, v_end, stops_inside). [R16]"""
    if D <= 1e-9:
        return [], 0.0, v0, False
    if halting:
        dstop = v0 * v0 / (2 * a)
        if dstop <= D:
            return ([(v0 / a, -a)] if v0 > 0 else []), dstop, 0.0, True
        ve = math.sqrt(max(0.0, v0 * v0 - 2 * a * D))
        return [((v0 - ve) / a, -a)], D, ve, False
    ve = min(ve_target, vm)
    if v0 * v0 - 2 * a * D >= ve * ve:
        vend = math.sqrt(max(0.0, v0 * v0 - 2 * a * D))
        return [((v0 - vend) / a, -a)], D, vend, False
    ve = min(ve, math.sqrt(v0 * v0 + 2 * a * D))
    vp = min(vm, math.sqrt((2 * a * D + v0 * v0 + ve * ve) / 2))
    vp = max(vp, ve)
    ph = []
    d1 = abs(vp * vp - v0 * v0) / (2 * a)
    d3 = (vp * vp - ve * ve) / (2 * a)
    dc = max(0.0, D - d1 - d3)
    if abs(vp - v0) > 1e-12:
        ph.append((abs(vp - v0) / a, a if vp > v0 else -a))
    if dc > 1e-12 and vp > 0:
        ph.append((dc / vp, 0.0))
    if vp - ve > 1e-12:
        ph.append(((vp - ve) / a, -a))
    return ph, D, ve, False


class Unit:
    def __init__(self, model, address, eeprom_path):
        self.model = model
        self.rate = MODELS[model]
        self.address = address
        self.eeprom_path = eeprom_path
        self.ee = bytearray(b'\xff' * 256)          # as shipped: all FF   [R30]
        if eeprom_path:
            try:
                with open(eeprom_path, 'rb') as f:
                    data = f.read(256)
                self.ee[:len(data)] = data
            except OSError:
                pass
        self.sim = None
        self.inputs = [0xFF, 0xFF, 0xFF]
        self.switch = [None] * NAXES
        self.rate_position = None
        self.unit_baud = None
        self.cnt = [0] * NAXES
        self.phys = [0] * NAXES
        self.exc = [[0, 0] for _ in range(NAXES)]
        self.brake_t = NEVER
        self.brake_mask = 0
        self.reset(0, power=True, deaf=False)

    # ------------------------------------------------------------------ reset
    def reset(self, t, power, deaf=True):
        """Power-on / J: the reset state of 13.5; the axes stop dead [R48]."""
        if getattr(self, 'mv', None) is not None:
            self.settle(t, self.seg_state(t)[0])
        self.mv = None
        self.queue = []
        self.wrun = None
        self.start_at = None
        self.halting = False
        self.pending = None          # 'H' or 'W' answer awaited
        self.cnt = [0] * NAXES
        self.st = [0] * 6            # ST0..ST5
        self.inta = self.intcom = self.stopbit = self.free = 0
        self.modal = {'A': 20, 'V': 1000, '$': 512, 'B': self.rate, 'T': 5, 'VK': False,
                      'VL': [self.rate] * NAXES, 'XM': 100}  # [R10][R11][R12]
        self.outputs = 0xFF
        self.spindle = 0             # [R55]
        self.cs = False
        self.index = 0
        self.packet = None
        self.kept = None
        self.last_answer = None
        self.mpg_mode = '&'          # "(po zapnuti nebo resetu)"   [R36]
        self.mpg_run = False
        self.frame = None
        self.frame_t0 = 0
        self.last_stop = t
        self.deaf_until = t + RESTART_NS if deaf else t
        # EEPROM configuration read at (re)start   [R31] (STEP polarity, PWM: stored only [R47])
        e = self.ee
        self.dirsign = [1 if (e[5] >> (4 + i)) & 1 else -1 for i in range(NAXES)]
        self.couple = e[0x0C] if e[0x0C] in (1, 2, 3) else 0
        if power:
            if self.rate_position is not None:
                tab = RATES_01 if e[0x0D] == 0x01 else RATES_FF
                self.unit_baud = tab[self.rate_position]
            else:
                self.unit_baud = None
        # brake outputs: "automaticky sepnut po pripojeni napajeni po uplynuti doby FD" [R28]
        mask = 0
        for addr, bit in ((1, 2), (2, 3), (3, 1)):
            if e[addr] == 0x08:
                mask |= 1 << bit
        self.brake_mask = mask
        self.brake_t = t + min(e[0xFD], 50) * 100_000_000 if mask else NEVER
        self.prev_irq = self.irq_levels()

    # --------------------------------------------------------------- helpers
    @property
    def now(self):
        return self.sim.now

    def run_bit(self):
        return 1 if (self.queue or self.mv is not None or self.wrun is not None
                     or self.mpg_run) else 0

    def moving(self):
        """'za chodu': axes moving, a W run, or vectors about to start (INTA=0). [R22]"""
        return (self.mv is not None or self.wrun is not None
                or self.start_at is not None or self.mpg_run)

    def st6(self):
        return (self.stopbit | (self.free << 1) | (self.intcom << 4)
                | (self.run_bit() << 6) | (self.inta << 7))

    def status_bytes(self):
        return self.st[:] + [self.st6()]

    def vparams(self, vec):
        Lm = vec.Lm
        sp = vec.speed
        acc = vec.acc * 1000.0
        if vec.vk:    # VK: V is the speed along the XYZ path   [R13]
            lx = math.sqrt(vec.d[0] ** 2 + vec.d[1] ** 2 + vec.d[2] ** 2)
            if lx > 0 and Lm > 0:
                sp *= Lm / lx
                acc *= Lm / lx
        sp = min(sp, self.rate)
        for i in range(NAXES):
            if vec.d[i]:
                sp = min(sp, vec.vl[i] * Lm / abs(vec.d[i]))
        if Lm < vec.short:           # short vector: only up to B   [R18]
            sp = min(sp, vec.brake)
        return max(sp, 1.0), max(acc, 1.0)

    def junction(self):
        """End speed of queue[0] from the brake map of following C vectors. [R19]"""
        q = self.queue
        n = min(len(q), LOOKAHEAD + 1)
        e = 0.0
        for j in range(n - 1, 0, -1):
            vj = q[j]
            if vj.kind != 'C':
                e = 0.0
                continue
            vm, a = self.vparams(vj)
            st = min(vm, math.sqrt(e * e + 2 * a * (vj.Lm - vj.s)))
            e = min(q[j - 1].brake, st)
        return e if n >= 2 else 0.0

    # ----------------------------------------------------------- positions
    def seg_state(self, t):
        g = self.mv
        if t >= g.t_end:
            return g.s_end, g.v_end
        dt = (t - g.t0) / 1e9
        s, v = g.s0, g.v0
        for dur, acc in g.phases:
            if dt <= dur:
                s2 = s + v * dt + 0.5 * acc * dt * dt
                return min(s2, g.s_end), v + acc * dt
            s += v * dur + 0.5 * acc * dur * dur
            v += acc * dur
            dt -= dur
        return g.s_end, g.v_end

    def pos_at_s(self, s):
        g = self.mv
        st = steps_at(g.vec, s)
        cnt = [self.base_cnt[i] + st[i] - self.base_steps[i] for i in range(NAXES)]
        phys = [self.base_phys[i] + self.dirsign[i]  # [R45]
                * (st[i] - self.base_steps[i])
                for i in range(NAXES)]
        return cnt, phys

    def positions(self, t=None):
        if t is None:
            t = self.now
        if self.mv is None:
            return self.cnt[:], self.phys[:]
        s, _ = self.seg_state(t)
        return self.pos_at_s(s)

    def note_exc(self, phys):
        for i in range(NAXES):
            lo, hi = self.exc[i]
            self.exc[i] = [min(lo, phys[i]), max(hi, phys[i])]

    def settle(self, t, s):
        cnt, phys = self.pos_at_s(s)
        self.cnt, self.phys = cnt, phys
        self.note_exc(phys)

    # -------------------------------------------------------------- motion
    def start_seg(self, vec, t, v0, fresh, halting=False, const=None):
        if fresh:
            self.base_cnt = self.cnt[:]
            self.base_phys = self.phys[:]
            self.base_steps = steps_at(vec, vec.s)
        g = Seg()
        g.vec = vec
        g.t0 = t
        g.halting = halting
        if fresh:
            g.s0 = vec.s
        else:
            g.s0 = vec.s
        g.v0 = v0
        D = vec.Lm - g.s0
        if const is not None:          # W legs: constant speed   [R34]
            ph = [(D / const, 0.0)] if D > 0 else []
            trav, ve, stop = D, const, False
        else:
            vm, a = self.vparams(vec)
            ve_t = 0.0 if halting else self.junction()
            ph, trav, ve, stop = plan(vm, a, D, v0, ve_t, halting)
        g.phases = ph
        g.s_end = g.s0 + trav
        g.v_end = ve
        g.stop = stop
        tot = sum(p[0] for p in ph)
        g.t_end = t + int(round(tot * 1e9))
        self.mv = g

    def replan(self, t, halting=None):
        g = self.mv
        if g is None or self.wrun is not None:
            return
        s, v = self.seg_state(t)
        if halting is None:
            halting = g.halting
        g.vec.s = s
        self.start_seg(g.vec, t, max(v, 0.0), fresh=False, halting=halting)

    def kick(self, t):
        if (self.mv is not None or self.wrun is not None or self.inta or self.mpg_run
                or self.sim_restarting(t)):
            return
        while self.queue and self.queue[0].Lm - self.queue[0].s <= 0:
            self.queue.pop(0)
        if not self.queue:
            self.start_at = None
            return
        vec = self.queue[0]
        start = t
        if vec.kind == 'L':       # dwell T between non-continuing vectors   [R15]
            start = max(t, self.last_stop + vec.dwell * 1_000_000)
        if start > t:
            self.start_at = start
            return
        self.start_at = None
        self.start_seg(vec, t, 0.0, fresh=True)

    def sim_restarting(self, t):
        return t < self.deaf_until

    def halt(self, t):
        """Start a stop ramp (H, interrupt). Returns True if a ramp is running."""
        self.inta = 1
        self.start_at = None
        if self.mv is not None and self.wrun is None:
            if not self.mv.halting:
                self.replan(t, halting=True)
            self.halting = True
            self.stopbit = 1
            if self.mv.t_end <= t:
                self.motion_event(t)
            return self.mv is not None
        return False

    def motion_next(self):
        if self.mv is not None:
            return self.mv.t_end
        if self.start_at is not None:
            return self.start_at
        return NEVER

    def motion_event(self, t):
        g = self.mv
        if g is None:
            if self.start_at is not None and self.start_at <= t:
                self.start_at = None
                self.kick(t)
            return
        if g.t_end > t:
            return
        vec = g.vec
        self.settle(t, g.s_end)
        if self.wrun is not None:
            self.w_event(t)
            return
        if g.stop or (g.halting and g.s_end < vec.Lm - 1e-9):
            # halted inside the vector: the rest stays in the queue
            vec.s = math.floor(g.s_end + 1e-6)
            self.settle(t, vec.s)
            self.mv = None
            if vec.s >= vec.Lm and self.queue and self.queue[0] is vec:
                self.queue.pop(0)
            self.end_halt(t)
            return
        # vector complete
        if self.queue and self.queue[0] is vec:
            self.queue.pop(0)
        self.mv = None
        v = g.v_end
        while self.queue and self.queue[0].Lm - self.queue[0].s <= 0:
            self.queue.pop(0)
        if g.halting:
            if self.queue and v > 1e-9:   # the stop ramp runs on through the queue [R52]
                self.start_seg(self.queue[0], t, v, fresh=True, halting=True)
                if self.mv.t_end <= t:
                    self.motion_event(t)
                return
            self.end_halt(t)
            return
        if self.queue and self.queue[0].kind == 'C' and v > 1e-9:
            self.start_seg(self.queue[0], t, v, fresh=True)
            if self.mv.t_end <= t:
                self.motion_event(t)
            return
        self.last_stop = t
        self.kick(t)
        if self.mv is not None and self.mv.t_end <= t:
            self.motion_event(t)

    def end_halt(self, t):
        self.halting = False
        self.stopbit = 0
        self.last_stop = t
        if self.pending == 'H':
            self.pending = None
            self.answer(0)

    # ------------------------------------------------------------------- W
    def w_event(self, t):
        w = self.wrun
        self.mv = None
        if w['leg'] == 1 and w['found']:
            ax = w['axis']
            d = [0] * NAXES
            d[ax] = -w['dir']
            vec = Vec(d, 'W', self.modal)
            w['leg'] = 2
            self.start_seg(vec, t, w['v2'], fresh=True, const=w['v2'])
            return
        self.wrun = None
        self.last_stop = t
        if w['found']:
            self.cnt[w['axis']] = 0             # W's zeroing   [R34]
            err = 0
        else:
            err = 5
        if self.pending == 'W':
            self.pending = None
            self.answer(err)

    # -------------------------------------------------------------- inputs
    def port_level(self, port):
        if port == 1:
            return self.inputs[1]
        if port == 2:
            return self.inputs[2] | 0x3F     # only IN14/IN15 exist   [R25]
        return 0xFF

    def irq_levels(self):
        out = []
        for k, port in ((0, 1), (1, 2)):
            lvl = self.port_level(port)
            pol = self.st[2 + k]
            active = ~(lvl ^ pol) & 0xFF         # active when level == polarity bit
            if port == 2:
                active &= 0xC0
            out.append(active & self.st[k])
        return out

    def check_irq(self, t):
        """Edge of (enabled AND active) -> ST4/ST5 cause, INTA, stop ramp.  [R23]"""
        cur = self.irq_levels()
        fired = False
        for k in range(2):
            rise = cur[k] & ~self.prev_irq[k] & 0xFF
            if rise:
                self.st[4 + k] |= rise
                fired = True
        self.prev_irq = cur
        if fired and self.wrun is None:
            self.halt(t)

    # ---------------------------------------------------------- timers
    def next_event(self):
        t = self.motion_next()
        if self.deaf_until > self.sim.now:
            t = min(t, self.deaf_until)
        if self.frame is not None:
            t = min(t, self.frame_t0 + WATCHDOG_NS)
        t = min(t, self.brake_t)
        return t

    def run_events(self, t):
        if self.frame is not None and self.frame_t0 + WATCHDOG_NS <= t:
            fr = self.frame
            self.frame = None
            if fr and self.addr_ok(fr[0]) and self.pending is None:  # [R5]
                self.answer(2)
        if self.brake_t <= t:
            self.brake_t = NEVER
            self.outputs &= ~self.brake_mask & 0xFF
        guard = 0
        while self.motion_next() <= t and guard < 100000:
            self.motion_event(t)
            guard += 1

    # ------------------------------------------------------------ receive
    def addr_ok(self, ch):           # [R49]
        return ch == str(self.address) or ch == '7'

    def rx(self, byte, t):
        if t < self.deaf_until:
            return                       # deaf while restarting
        if self.unit_baud is not None and self.unit_baud != self.sim.baud:
            self.frame = None            # garbled at a foreign rate   [R42]
            return
        c = chr(byte)
        if c == '!':
            self.frame = ''              # a new '!' restarts the frame   [R6]
            self.frame_t0 = t
            return
        if self.frame is None:
            return
        if byte == CR:
            fr = self.frame
            self.frame = None
            self.on_frame(fr, t)
            return
        if byte == 0x0A:
            return
        self.frame += c

    def answer(self, err, params=None, raw=None):
        if raw is not None:
            self.sim.send(raw)
            return
        code = (self.inta << 3) | err     # [R44]
        text = '%X' % code
        if params:
            text += ',' + ','.join(params)
        if self.cs:
            text += ',' + '%02X' % (sum((text + ',').encode()) & 0xFF)
        data = text.encode() + b'\r'
        self.last_answer = data
        self.sim.send(data)

    def on_frame(self, fr, t):
        if self.pending is not None:
            return                       # busy with H/W   [R8]
        if not fr or not self.addr_ok(fr[0]):
            return
        if len(fr) > MAXFRAME:
            self.answer(4)
            return
        addr = fr[0]
        body = fr[1:]
        if self.cs:
            full = '!' + fr
            k = full.rfind(',')
            ok = False
            if k >= 2 and re.match(r'^[0-9A-Fa-f]{2}$', full[k + 1:]):
                ok = (sum(full[:k + 1].encode('latin-1')) & 0xFF) == int(full[k + 1:], 16)
            if not ok:                   # checksum wrong: not executed   [R3]
                if self.packet is not None:
                    self.packet['err'] = self.packet['err'] or 4
                    if body.startswith('*E'):
                        self.packet = None
                        self.answer(4)
                    return
                self.answer(4)
                return
            body = full[2:k]
        if body == '>':                  # [R38]
            if self.last_answer is not None:
                self.answer(0, raw=self.last_answer)
            else:
                self.answer(0)
            return
        if body == '@':                  # [R37]
            self.answer(0, [str(self.index)])
            return
        self.index = (self.index + 1) & 0xFF
        if self.packet is not None and not body.startswith('*'):
            self.packet['cmds'].append(body)
            if addr != '0' or not (body.startswith('C') or body.startswith('B')):
                self.packet['err'] = self.packet['err'] or 4      # [R4]
            return
        try:
            res = self.execute(addr, body, t)
        except CmdError as e:
            self.answer(e.code)
            return
        except Exception:               # never let a bug end the co-simulation
            import traceback
            traceback.print_exc(file=sys.stderr)
            self.answer(4)
            return
        if res is None:
            return
        err, prm = res
        self.answer(err, prm)

    # ------------------------------------------------------------ commands
    def execute(self, addr, b, t):
        if addr == '7' and str(self.address) != '7':
            return self.exec7(b, t)
        return self.exec0(b, t)

    def common(self, b, t):
        """Commands answered on address 0 and 7 (13.7)."""
        if b == '?':
            return 0, ['IP114/%d x16 16.9.2018' % (self.rate // 1000)]   # [R2]
        if b == 'Q':
            return 0, ['16091801']                                       # [R2]
        if b == 'J':
            self.answer(0)
            self.reset(t, power=False)                                   # [R39]
            return None
        if b.startswith('%'):
            if b == '%+':
                self.cs = True
            elif b == '%-':
                self.cs = False
            else:
                raise CmdError(4)
            return 0, None
        if b.startswith('E'):
            return self.eeprom_cmd(b)
        return False

    def exec7(self, b, t):
        r = self.common(b, t)
        if r is not False:
            return r
        if b.startswith('V'):
            n = pint(b[1:], 0, 1000)
            self.spindle = n
            if n == 0:
                self.outputs |= 0x01
            else:
                self.outputs &= 0xFE
            return 0, None
        raise CmdError(3)

    def eeprom_cmd(self, b):
        m = re.match(r'^E(R|FR|UR|W|FW|UW)(.*)$', b)
        if not m:
            raise CmdError(3)
        op, rest = m.group(1), m.group(2)
        size = {'R': 1, 'W': 1, 'FR': 4, 'FW': 4, 'UR': 4, 'UW': 4}[op]
        if op.endswith('R'):
            a = phex(rest)
            if a + size > 256:
                raise CmdError(5)
            if op == 'R':
                return 0, ['%02X' % self.ee[a]]
            raw = bytes(self.ee[a:a + 4])
            if op == 'FR':
                return 0, [fmt_float(struct.unpack('<f', raw)[0])]
            return 0, [str(struct.unpack('<I', raw)[0])]
        p = params(rest, 2, 2)
        a = phex(p[0])
        if a + size > 256:
            raise CmdError(5)
        if op == 'W':
            x = phex(p[1])
            data = bytes([x])
        elif op == 'FW':
            if not RE_FLOAT.match(p[1]):
                raise CmdError(4)
            f = float(p[1])
            try:
                data = struct.pack('<f', f)
            except OverflowError:
                raise CmdError(5)
        else:
            x = pint(p[1], 0, 0xFFFFFFFF)        # decimal   [R32]
            data = struct.pack('<I', x)
        self.ee[a:a + size] = data
        if self.eeprom_path:
            try:
                with open(self.eeprom_path, 'wb') as f:
                    f.write(self.ee)
            except OSError:
                pass
        return 0, None

    def vector(self, kind, rest, t):
        p = params(rest, 3, 4)          # [R50]
        d = pints(p, -2147483647, 2147483647)
        while len(d) < NAXES:
            d.append(0)
        if self.couple:
            d[3] = d[self.couple - 1]              # A coupled   [R29]
        if self.mpg_run:
            raise CmdError(7)
        zero = max(abs(x) for x in d) == 0
        if kind == 'L':
            if self.queue or self.mv is not None or self.wrun is not None:
                raise CmdError(1)                 # L only into an empty unit   [R14]
            if zero:
                return 0, None                    # [R20]
        else:
            if self.kept is not None:
                raise CmdError(1)                 # after K only L   [R35]
            if len(self.queue) >= QMAX:
                raise CmdError(1)
            if zero:
                return 0, None
        self.queue.append(Vec(d, kind, self.modal))
        if self.mv is not None and not self.mv.halting:
            self.replan(t)
        else:
            self.kick(t)
        return 0, None

    def exec0(self, b, t):
        r = self.common(b, t)
        if r is not False:
            return r
        c = b[:1]
        rest = b[1:]
        m = self.modal
        if c == 'L' or c == 'C':
            return self.vector(c, rest, t)
        if c == '*':
            if b == '*S':
                self.packet = {'cmds': [], 'err': 0}
                return None                        # answered at *E   [R4]
            if b.startswith('*E'):
                return self.packet_end(rest[1:], t)
            raise CmdError(3)
        if c == 'T':
            m['T'] = pint(rest, 1, 24)
            return 0, None
        if c == '$':
            m['$'] = pint(rest, 1, 2147483647)
            return 0, None
        if c == 'A':
            m['A'] = pint(rest, 1, 100000)          # [R11]
            return 0, None
        if c == 'B':
            m['B'] = pint(rest, 10, self.rate)
            return 0, None
        if c == 'V':
            if b == 'VK':
                m['VK'] = True
                return 0, None
            if b == 'VN':
                m['VK'] = False
                return 0, None
            if b.startswith('VL'):
                p = params(b[2:], 3, 4)
                vals = pints(p, 10, self.rate)       # [R12]
                m['VL'] = vals + m['VL'][len(vals):] if len(vals) == 4 else vals + [m['VL'][3]]
                return 0, None
            m['V'] = pint(rest, 10, self.rate)                   # [R10]
            return 0, None
        if c == 'X':
            return self.exchange(b, t)
        if b == 'P':                     # [R54]
            cnt, _ = self.positions(t)
            return 0, [str(cnt[0]), str(cnt[1])]
        if b == 'PF':
            cnt, _ = self.positions(t)
            return 0, [str(cnt[0]), str(cnt[1]), str(cnt[2])]
        if c == 'N':
            if rest == '':
                if self.run_bit():
                    raise CmdError(7)
                self.cnt = [0] * NAXES                             # [R24]
                return 0, None
            ax = 'XYZ'.find(rest[:1])
            if ax < 0 or rest[:1] == '':
                raise CmdError(4)
            v = pint(rest[1:], -2147483647, 2147483647)
            if self.run_bit():
                raise CmdError(7)
            self.cnt[ax] = v
            return 0, None
        if c == 'W':
            return self.wcmd(rest, t)
        if c == 'Y':
            return self.mpg(rest, t)
        if b == 'K':
            if self.moving() or self.halting:
                raise CmdError(7)
            if self.kept is not None:
                raise CmdError(5)                                  # [R35]
            self.kept = {'q': self.queue, 'st4': self.st[4], 'st5': self.st[5],
                         'f': (self.inta, self.intcom, self.stopbit, self.free)}
            self.queue = []
            self.st[4] = self.st[5] = 0
            self.inta = self.intcom = self.stopbit = self.free = 0
            return 0, None
        if b == 'R':
            if self.moving() or self.halting or self.queue:
                raise CmdError(7)
            if self.kept is None:
                raise CmdError(5)
            k = self.kept
            self.kept = None
            self.queue = k['q']
            self.st[4], self.st[5] = k['st4'], k['st5']
            self.inta, self.intcom, self.stopbit, self.free = k['f']
            self.kick(t)
            return 0, None
        if b == 'H':                     # [R43]
            self.intcom = 1
            if self.wrun is None and self.halt(t):
                self.pending = 'H'
                return None
            self.stopbit = 0
            return 0, None
        if b == 'D':
            if self.moving() or self.halting:
                raise CmdError(7)
            self.queue = []
            self.start_at = None
            self.st[4] = self.st[5] = 0
            self.inta = self.intcom = self.stopbit = self.free = 0
            return 0, None
        if b == 'G':
            if self.halting or self.wrun is not None:
                raise CmdError(7)                                  # [R21]
            if not self.inta:
                return 6, None
            self.inta = self.intcom = self.stopbit = 0
            self.st[4] = self.st[5] = 0
            self.prev_irq = self.irq_levels()
            if not self.queue:
                return 6, None
            self.kick(t)
            return 0, None
        if c == 'O':
            p = params(rest, 2, 2)
            port = pint(p[0], 0, 0) if RE_UINT.match(p[0]) else phex(p[0])
            if port != 0:
                raise CmdError(5)
            self.outputs = phex(p[1])                               # [R26]
            return 0, None
        if c == 'I':
            n = pint(rest, 0, 9)
            if n not in (1, 2):
                raise CmdError(5)                                   # [R25]
            return 0, ['%02X' % self.port_level(n)]
        if b.startswith('SR'):           # [R58]
            n = pint(b[2:], 0, 255)
            if n > 6:
                raise CmdError(5)
            return 0, ['%02X' % self.status_bytes()[n]]
        if b.startswith('SW'):
            p = params(b[2:], 2, 2)
            n = pint(p[0], 0, 255)
            x = phex(p[1])
            if n > 6:
                raise CmdError(5)
            if n == 6:
                self.sw6(x, t)
            else:
                self.st[n] = x
                if n < 4:
                    self.check_irq(t)
            return 0, None
        if b == 'F':
            f = self.st6() | (0x20 if len(self.queue) >= QMAX else 0)
            return 0, ['%02X' % f]
        raise CmdError(3)                                          # [R46]

    def sw6(self, x, t):                                           # [R27]
        self.free = (x >> 1) & 1
        self.intcom = (x >> 4) & 1
        want = (x >> 7) & 1
        if want and not self.inta:
            self.halt(t)
        elif not want and self.inta and not self.halting:
            self.inta = 0                # nothing is restarted: that is G's job

    def exchange(self, b, t):
        m = self.modal
        if b == 'XA':
            sp = m['V'] * m['XM'] / 100.0
            for v in self.queue:
                v.speed = sp
        elif b == 'XU':
            for v in self.queue:
                v.speed = min(self.rate, v.speed * 17 / 16)
        elif b == 'XD':
            for v in self.queue:
                v.speed = max(10.0, v.speed * 15 / 16)
        elif b.startswith('XM'):
            n = pint(b[2:], 1, 1000)                                # [R9]
            m['XM'] = n
            sp = m['V'] * n / 100.0
            for v in self.queue:
                v.speed = sp
        else:
            raise CmdError(3)
        if self.mv is not None and not self.mv.halting:
            self.replan(t)
        return 0, None

    def wcmd(self, rest, t):
        # "Wn1,n2,n3,n4,n5", e.g. "!0WY-20000,1000,2000,500": axis letter and n2 share a field
        p = params(rest, 4, 4)
        if not p[0]:
            raise CmdError(4)
        ax = 'XYZ'.find(p[0][:1].upper())
        n2 = pint(p[0][1:], -2147483647, 2147483647)
        if ax < 0:
            raise CmdError(5)
        n3 = pint(p[1], 10, self.rate)
        pint(p[2], 1, 2147483647)
        n5 = pint(p[3], 10, self.rate)
        if n2 == 0:
            raise CmdError(5)
        if self.run_bit():
            raise CmdError(7)
        dir_c = 1 if n2 > 0 else -1
        dir_p = dir_c * self.dirsign[ax]
        found = False
        k1 = abs(n2)
        sw = self.switch[ax]
        if sw is not None:
            dist = (sw - self.phys[ax]) * dir_p
            if 0 <= dist <= abs(n2):
                found, k1 = True, dist
        else:                          # reference input IN0..IN2 with ST2 polarity [R34]
            lvl = (self.port_level(1) >> ax) & 1
            if lvl == ((self.st[2] >> ax) & 1):
                found, k1 = True, 0
        self.wrun = {'axis': ax, 'dir': dir_c, 'found': found, 'leg': 1, 'v2': n5}
        d = [0] * NAXES
        d[ax] = dir_c * k1
        vec = Vec(d, 'W', self.modal)
        self.pending = 'W'
        self.start_seg(vec, t, n3, fresh=True, const=n3)
        if self.mv.t_end <= t:
            self.motion_event(t)
        return None

    def mpg_valid(self):                                            # [R36]
        e = self.ee
        mode = e[6]
        if mode not in (0x01, 0x02, 0x81, 0x82):
            return False

        def f(a):
            return struct.unpack('<f', bytes(e[a:a + 4]))[0]

        def u(a):
            return struct.unpack('<I', bytes(e[a:a + 4]))[0]
        axes = 4 if mode & 0x80 else 3
        for i in range(axes):
            for base, lo, hi in ((0x10, 0, 10000), (0x20, 0, 10000), (0x30, 1, 10000)):
                v = f(base + 4 * i)
                if not (lo <= v <= hi):
                    return False
        if not (1 <= f(0x40) <= 10000):
            return False
        vmax = f(0x44)
        if not (vmax > 0):
            return False
        for i in range(axes):
            if vmax * f(0x30 + 4 * i) > self.rate / 4:
                return False
        if not (1 <= u(0x48) <= 2000):
            return False
        return True

    def mpg(self, rest, t):          # [R36][R53]
        if rest not in ('+', '&', '-'):
            raise CmdError(4)
        if rest == '-':
            self.mpg_mode = '-'
            self.mpg_run = False
        else:
            if self.queue or self.mv is not None or self.wrun is not None:
                raise CmdError(7)
            if not self.mpg_valid():
                raise CmdError(5)
            self.mpg_mode = rest
            self.mpg_run = True
        return 0, ['Y' + rest]

    def packet_end(self, nstr, t):   # [R4][R51]
        pk = self.packet
        if pk is None:
            raise CmdError(4)                                     # [R4]
        self.packet = None
        n = len(pk['cmds'])
        if not RE_UINT.match(nstr or ''):
            return 4, [str(n)]
        if int(nstr) != n:
            return 2, [str(n)]
        if pk['err']:
            return pk['err'], [str(n)]
        # validate everything first: the packet is all or nothing
        m = self.modal
        nc = 0
        for cmd in pk['cmds']:
            try:
                if cmd[0] == 'B':
                    pint(cmd[1:], 10, self.rate)
                else:
                    p = params(cmd[1:], 3, 4)
                    d = pints(p, -2147483647, 2147483647)
                    if any(d):
                        nc += 1
            except CmdError as e:
                return e.code, [str(n)]
        if self.mpg_run:
            return 7, [str(n)]
        if self.kept is not None and nc:
            return 1, [str(n)]
        if len(self.queue) + nc > QMAX:
            return 1, [str(n)]
        for cmd in pk['cmds']:
            if cmd[0] == 'B':
                m['B'] = int(cmd[1:])
            else:
                self.vector('C', cmd[1:], t)
        return 0, [str(n)]

    # ----------------------------------------------------------------- rig
    def state(self):
        cnt, phys = self.positions()
        self.note_exc(phys)
        return {
            'profile': self.model,
            'addresses': [self.address],
            'time_ns': self.now,
            'position': cnt,
            'physical': phys,
            'excursion': [list(x) for x in self.exc],
            'status': ['%02X' % x for x in self.status_bytes()],
            'outputs': '%02X' % self.outputs,
            'spindle': self.spindle,
            'rate_position': self.rate_position,
            'rate': self.unit_baud,
            'inputs': {'0': '%02X' % self.inputs[0], '1': '%02X' % self.inputs[1],
                       '2': '%02X' % self.inputs[2]},
            'queue': len(self.queue),
            'index': self.index,
            'checksums': self.cs,
            'modal': {'V': self.modal['V'], 'A': self.modal['A'], 'B': self.modal['B'],
                      '$': self.modal['$'], 'T': self.modal['T'], 'VK': self.modal['VK'],
                      'VL': self.modal['VL'], 'XM': self.modal['XM']},
            'mpg': self.mpg_mode,
            'kept': self.kept is not None,
            'packet_open': self.packet is not None,
            'restarting': self.now < self.deaf_until,
            'eeprom': self.eeprom_path,
        }


class Sim:
    def __init__(self, unit, out):
        self.unit = unit
        unit.sim = self
        self.out = out
        self.now = 0
        self.baud = 115200
        self.b = round(1e10 / 115200)
        self.rxq = []            # (t, byte) to the unit
        self.txfifo = []         # bytes waiting to be sent
        self.txcur = None        # (byte, t_complete)
        self.reported = []

    def send(self, data):            # [R56]
        self.txfifo.extend(data)
        if self.txcur is None:
            self._next_tx(self.now)

    def _next_tx(self, t):
        if self.txfifo:
            self.txcur = (self.txfifo.pop(0), t + self.b)
        else:
            self.txcur = None

    def advance(self, limit, crstop):
        u = self.unit
        while True:
            tu = u.next_event()
            tt = self.txcur[1] if self.txcur else NEVER
            tr = self.rxq[0][0] if self.rxq else NEVER
            t = min(tu, tt, tr)
            if t > limit:
                self.now = limit
                return False
            self.now = t
            if tu <= t:
                u.run_events(t)
                continue
            if tt <= t:
                byte = self.txcur[0]
                self.reported.append((t, byte))
                self._next_tx(t)
                if byte == CR and crstop:
                    return True
                continue
            _, byte = self.rxq.pop(0)
            u.rx(byte, t)

    def due_now(self):
        """Run the unit's events a rig action made due at this very instant."""
        for _ in range(1000):
            if self.unit.next_event() > self.now:
                break
            self.unit.run_events(self.now)

    def flush_rx(self):
        lines = ['rx %d %02X' % (t, b) for t, b in self.reported]
        self.reported = []
        return lines

    def do_tx(self, hexs, T=None):
        data = bytes.fromhex(hexs)
        start = self.now
        for i, byte in enumerate(data):
            self.rxq.append((start + (i + 1) * self.b, byte))
        end = start + len(data) * self.b
        if T is not None and T < end:
            raise ValueError('T before the end of the bytes')
        self.advance(end, False)
        cr = any(b == CR for _, b in self.reported)
        if T is not None and not cr:
            self.advance(T, True)
        return self.flush_rx() + ['now %d' % self.now]

    def next_cmd(self):              # [R57]
        u = self.unit
        t = min(u.next_event(), self.txcur[1] if self.txcur else NEVER)
        return 'next none' if t >= NEVER else 'next %d' % t

    def handle(self, line):
        w = line.split()
        if not w:
            return None
        c = w[0]
        u = self.unit
        if c in ('in', 'switch', 'state', 'power-on', 'rate') and w[-1].startswith('@'):
            if w[-1] != '@%d' % u.address:
                return ['error: no unit at address %s' % w[-1][1:]]
            w = w[:-1]
        if c in ('quit', 'exit'):
            raise SystemExit(0)
        if c == 'help':
            return ['commands: tx HEX [T] | until T | next | baud N | batch D HEX ... | '
                    'in PORT XX | switch AXIS POS|none | rate POS|none | power-on | state | quit']
        if c == 'tx':
            if len(w) not in (2, 3) or not re.match(r'^([0-9A-Fa-f]{2})+$', w[1]):
                return ['error: usage: tx HEX [T]']
            T = None
            if len(w) == 3:
                if not num(w[2]):
                    return ['error: bad instant']
                T = int(w[2])
                if T < self.now + len(w[1]) // 2 * self.b:
                    return ['error: T before the end of the bytes']
            return self.do_tx(w[1], T)
        if c == 'until':
            if len(w) != 2 or not num(w[1]):
                return ['error: usage: until T']
            T = int(w[1])
            if T < self.now:
                return ['error: until before now']
            self.advance(T, True)
            return self.flush_rx() + ['now %d' % self.now]
        if c == 'next':
            if len(w) != 1:
                return ['error: usage: next']
            return [self.next_cmd()]
        if c == 'baud':
            if len(w) != 2 or not num(w[1]) or int(w[1]) <= 0:
                return ['error: usage: baud N']
            self.baud = int(w[1])
            self.b = round(1e10 / self.baud)
            return ['ok']
        if c == 'batch':
            if len(w) < 3 or len(w) % 2 != 1:
                return ['error: usage: batch D HEX [D HEX ...]']
            pairs = []
            for i in range(1, len(w), 2):
                if not num(w[i]) or not re.match(r'^([0-9A-Fa-f]{2})+$', w[i + 1]):
                    return ['error: malformed batch']
                pairs.append((int(w[i]), w[i + 1]))
            out = []
            for D, hx in pairs:
                T = self.now + len(hx) // 2 * self.b + D
                part = self.do_tx(hx, T)
                out += part
                if not any(x.startswith('rx ') and x.endswith(' 0D') for x in part):
                    break            # batch-stops
            return out
        if c == 'in':
            if (len(w) != 3 or w[1] not in ('0', '1', '2')
                    or not re.match(r'^[0-9A-Fa-f]{2}$', w[2])):
                return ['error: usage: in PORT XX']
            u.inputs[int(w[1])] = int(w[2], 16)
            u.check_irq(self.now)
            self.due_now()
            return ['ok']
        if c == 'switch':
            if len(w) != 3 or w[1].upper() not in ('X', 'Y', 'Z', 'A'):
                return ['error: usage: switch AXIS POS|none']
            ax = 'XYZA'.index(w[1].upper())
            if w[2] == 'none':
                u.switch[ax] = None
            elif re.match(r'^[+-]?[0-9]{1,20}$', w[2]):
                u.switch[ax] = int(w[2])
            else:
                return ['error: bad position']
            return ['ok']
        if c == 'rate':
            if len(w) != 2:
                return ['error: usage: rate POS|none']
            if w[1] == 'none':
                u.rate_position = None
            elif w[1] in ('0', '1', '2', '3'):
                u.rate_position = int(w[1])
            else:
                return ['error: rate position 0..3']
            return ['ok']
        if c == 'power-on':
            if len(w) != 1:
                return ['error: usage: power-on']
            u.reset(self.now, power=True)
            self.due_now()
            return ['ok']
        if c == 'state':
            if len(w) != 1:
                return ['error: usage: state']
            return [json.dumps(u.state())]
        return ['error: unknown command %r' % c]


def num(s):
    return bool(re.match(r'^[0-9]{1,20}$', s))


def main():
    ap = argparse.ArgumentParser(description='GVE114 simulator (clone)')
    ap.add_argument('--cosim', action='store_true', help='speak cosim.md on stdin/stdout')
    ap.add_argument('--model', default='GVE114-500', choices=sorted(MODELS))
    ap.add_argument('--address', type=int, default=0, choices=range(0, 7))
    ap.add_argument('--eeprom', default=None, help='EEPROM image file (kept across runs)')
    a = ap.parse_args()
    if not a.cosim:
        ap.error('only --cosim is implemented')
    sim = Sim(Unit(a.model, a.address, a.eeprom), sys.stdout)
    out = sys.stdout
    out.write('cosim 1 batch batch-stops\n')
    out.flush()
    for line in sys.stdin:
        try:
            rep = sim.handle(line.strip('\r\n'))
        except SystemExit:
            return 0
        except Exception as e:
            import traceback
            traceback.print_exc(file=sys.stderr)
            rep = ['error: internal: %s' % e]
        if rep is None:
            continue
        out.write('\n'.join(rep) + '\n')
        out.flush()
    return 0


if __name__ == '__main__':
    sys.exit(main())
