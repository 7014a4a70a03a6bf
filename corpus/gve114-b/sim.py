#!/usr/bin/env python3
"""GVE114 hardware interpolator simulator (one unit), written from the vendor
manual alone (given/GVE114-manual.txt).  Python 3.11 standard library only.

Structure follows a microcontroller port:
  * Motion      - the timer interrupt: a DDA/Bresenham interpolator clocked at
                  the model's interpolation rate (50/125/200/500 kHz), with a
                  1 ms ramp tick that updates the integer velocity (steps/s).
                  Step instants are computed in closed form between ramp ticks
                  (identical to running the DDA tick by tick).
  * Unit        - UART receive state machine, watchdog, command dispatcher,
                  status words, EEPROM (256 bytes, read at reset), outputs,
                  spindle (address 7), packets, checksums, KEEP/RESTORE, MPG.
  * CoSim       - given/cosim.md line protocol in virtual time (never sleeps).

Every interpretation of the manual is numbered in READINGS.md; "R<n>" in the
comments points there.
"""
import argparse
import copy
from decimal import Decimal
import json
import math
import re
import struct
import sys
from collections import deque

MODELS = {'GVE114-50': 50000, 'GVE114-125': 125000,
          'GVE114-200': 200000, 'GVE114-500': 500000}
QUEUE_CAP = 2048            # vectors, the executing one included (R18)
WATCHDOG_NS = 100_000_000   # a frame must be complete 100 ms after its '!' (R8)
RESTART_NS = 2_000_000_000  # 13.5 "cca po 2s"
RAMP_NS = 1_000_000         # ramp tick 1 ms (R28)
LOOKAHEAD = 32              # vectors looked at for the braking map (R29)
QID = '25022504'            # 13.6.1 example processor ID (R2)
MAXI = 2147483647
BIG = 1 << 62
AXES = 'XYZA'


def wrap32(v):
    v &= 0xFFFFFFFF
    return v - (1 << 32) if v & 0x80000000 else v


def f32(x):
    return struct.unpack('<f', struct.pack('<f', x))[0]


def fmt_f32(x):
    if math.isnan(x):
        return 'nan'
    if math.isinf(x):
        return 'inf' if x > 0 else '-inf'
    for p in range(1, 10):
        s = '%.*g' % (p, x)
        if f32(float(s)) == x:
            break
    if 1e-6 <= abs(x) < 1e15 or x == 0:
        s = format(Decimal(s), 'f')
        if '.' in s:
            s = s.rstrip('0').rstrip('.')
        if s in ('-0', ''):
            s = '0' if not s.startswith('-') else '-0'
    return s


class Err(Exception):
    def __init__(self, code):
        super().__init__(code)
        self.code = code


# ---------------------------------------------------------------------------
# Interpolator (timer interrupt)
# ---------------------------------------------------------------------------
class Vec:
    __slots__ = ('kind', 'd', 'ad', 'sg', 'n', 'k', 'vcmd', 'B', 'A', 'short', 'vk')

    def __init__(self, kind, d, vcmd, B=0, A=1, short=False, vk=False):
        self.kind = kind
        self.d = list(d)
        self.ad = [abs(x) for x in d]
        self.sg = [1 if x >= 0 else -1 for x in d]
        self.n = max(self.ad)
        self.k = 0
        self.vcmd = vcmd
        self.B = B
        self.A = A
        self.short = short
        self.vk = vk


class Motion:
    """Everything the timer ISR owns.  Self-contained so that it can be
    deep-copied to look ahead for the cosim 'next' command."""

    def __init__(self, F):
        self.F = F
        self.TP = 10**9 // F          # tick period ns (2000/5000/8000/20000)
        self.R = F // 1000            # ticks per 1 ms ramp period
        self.cnt = [0, 0, 0, 0]       # position counters (what PF reads)
        self.phys = [0, 0, 0, 0]      # where the axes physically are
        self.exc = [[0, 0] for _ in range(4)]
        self.dirsign = [1, 1, 1, 1]
        self.aslave = 0
        self.jn = 0                   # next tick index to process
        self.in1 = 0xFF
        self.st2 = 0
        self.reset()

    def reset(self):
        self.queue = deque()
        self.cur = None
        self.v = 0
        self.acc = 0
        self.stopping = False
        self.inta = False
        self.intcom = False
        self.valid_to = 0
        self.planned_at = -1
        self.dwell_until = 0
        self.T = 0
        self.w = None
        self.mpg = False
        self.xm = 100
        self.vl = [0, 0, 0, 0]
        self.events = []

    # -- derived state -------------------------------------------------
    def run_bit(self):
        return bool(self.cur is not None or self.queue or self.w or self.mpg)

    def moving(self):
        return bool(self.stopping or self.w or
                    ((self.cur is not None or self.queue) and not self.inta))

    def held_count(self):
        return len(self.queue) + (1 if self.cur is not None else 0)

    def vmax(self, vec):
        if vec.kind == 'W':
            return vec.vcmd
        v = vec.vcmd * self.xm // 100
        if vec.vk:
            d3 = vec.d[0] ** 2 + vec.d[1] ** 2 + vec.d[2] ** 2
            if d3 > 0:
                v = int(v * vec.n / math.sqrt(d3))
        if vec.short:
            v = min(v, vec.B)
        for i in range(4):
            if vec.ad[i] and self.vl[i]:
                v = min(v, self.vl[i] * vec.n // vec.ad[i])
        return max(1, min(v, self.F))

    def junction(self):
        """Speed the current vector has to reach at its end (braking map)."""
        vecs = [self.cur]
        for i, q in enumerate(self.queue):
            if i >= LOOKAHEAD:
                break
            vecs.append(q)
        ex = 0
        for i in range(len(vecs) - 1, 0, -1):
            vi = vecs[i]
            if vi.kind != 'C':
                ex = 0
                continue
            entry = math.isqrt(ex * ex + 2000 * vi.A * (vi.n - vi.k))
            prev = vecs[i - 1]
            ex = min(prev.B, self.vmax(prev), self.vmax(vi), entry)
        return ex

    # -- position bookkeeping ------------------------------------------
    def _move_axis(self, i, delta):
        self.cnt[i] = wrap32(self.cnt[i] + delta)
        p = self.phys[i] + delta * self.dirsign[i]
        self.phys[i] = p
        e = self.exc[i]
        if p < e[0]:
            e[0] = p
        if p > e[1]:
            e[1] = p

    def adv(self, vec, s):
        k0 = vec.k
        k1 = k0 + s
        vec.k = k1
        n = vec.n
        h = n // 2
        for i in range(4):
            a = vec.ad[i]
            if not a:
                continue
            delta = ((k1 * a + h) // n - (k0 * a + h) // n) * vec.sg[i]
            if delta:
                self._move_axis(i, delta)
                if self.aslave == i + 1 and i < 3:
                    self._move_axis(3, delta)

    # -- ISR pieces ------------------------------------------------------
    def ref_active(self, axis):
        return ((self.in1 >> axis) & 1) == ((self.st2 >> axis) & 1)

    def plan(self, j):
        """Ramp tick at tick index j.  Returns True if an event happened."""
        t = j * self.TP
        self.valid_to = j + self.R
        if self.cur is None:
            if self.inta or self.mpg or not self.queue:
                return False
            if self.queue[0].kind == 'L' and t < self.dwell_until:
                return False
            self.cur = self.queue.popleft()
            self.v = 0
            self.acc = 0
        cur = self.cur
        if cur.kind == 'W':
            w = self.w
            if not w['rig']:
                act = self.ref_active(w['axis'])
                if w['phase'] == 1 and act:
                    w['found'] = True
                    cur.n = cur.k
                    cur.ad[w['axis']] = cur.k
                elif w['phase'] == 2 and not act:
                    w['released'] = True
                    cur.n = cur.k
                    cur.ad[w['axis']] = cur.k
            if cur.k >= cur.n:
                self.end_vector(t)
                return True
            self.v = cur.vcmd
            if w['rig']:
                self.valid_to = j + self.R * (BIG // (self.R * 4))
            return False
        if self.inta and not self.stopping:
            self.v = 0
            self.acc = 0
            return False
        if cur.k >= cur.n:
            self.end_vector(t)
            return True
        a = cur.A
        ve = self.junction()
        rem = cur.n - cur.k
        vallow = math.isqrt(ve * ve + 2000 * a * rem)
        if self.stopping:
            vn = min(self.v - a, vallow)
            if vn <= 0:
                self.v = 0
                self.acc = 0
                self.stopping = False
                self.events.append(('stopped',))
                return True
            self.v = vn
            return False
        vm = self.vmax(cur)
        vn = min(self.v + a, vallow, max(vm, self.v - a))
        vn = max(vn, 1)
        if vn == self.v and vallow > vn:
            # cruise: nothing changes until the braking point comes near
            thr = -(-(vn * vn - ve * ve) // (2000 * a)) if vn > ve else 0
            s_ok = rem - thr - vn // 1000 - 2
            if s_ok > 0:
                m = (s_ok * self.F // vn) // self.R
                if m >= 2:
                    self.valid_to = j + m * self.R
        self.v = vn
        return False

    def end_vector(self, t):
        cur = self.cur
        self.cur = None
        self.valid_to = 0
        self.events.append(('vend',))
        if cur.kind == 'W':
            self.w_end(t)
            return
        nx = self.queue[0] if self.queue else None
        if nx is not None and nx.kind == 'C' and not (self.inta and not self.stopping):
            self.cur = self.queue.popleft()      # continues at the current speed
            return
        self.v = 0
        self.acc = 0
        self.dwell_until = t + self.T * 1_000_000
        if self.stopping:
            self.stopping = False
            self.events.append(('stopped',))

    def start_w(self, axis, n2, n3, n4, n5, sw):
        s = 1 if n2 > 0 else -1
        L = abs(n2)
        w = {'axis': axis, 'phase': 1, 's': s, 'n4': n4, 'v5': n5,
             'rig': sw is not None, 'found': False, 'released': False}
        if sw is not None:
            pd = s * self.dirsign[axis]
            dist = (sw - self.phys[axis]) * pd
            if 0 <= dist <= L:
                w['found'] = True
                n = dist
            else:
                n = L
        else:
            n = L
        d = [0, 0, 0, 0]
        d[axis] = s * n
        self.w = w
        self.cur = Vec('W', d, n3)
        self.v = 0
        self.acc = 0
        self.valid_to = 0

    def w_end(self, t):
        w = self.w
        ax = w['axis']
        if w['phase'] == 1:
            if not w['found']:
                self.w = None
                self.v = 0
                self.events.append(('wdone', 5))
                return
            w['phase'] = 2
            n = 1 if w['rig'] else w['n4']
            d = [0, 0, 0, 0]
            d[ax] = -w['s'] * n
            self.cur = Vec('W', d, w['v5'])
            self.v = 0
            self.acc = 0
            return
        ok = w['rig'] or w['released']
        if ok:
            self.cnt[ax] = 0
        self.w = None
        self.v = 0
        self.acc = 0
        self.events.append(('wdone', 0 if ok else 5))

    def halt(self):
        """Stop request (H, input interrupt, SW6 INTA).  True if a ramp runs."""
        self.inta = True
        self.valid_to = 0
        if self.cur is not None and self.v > 0 and self.cur.kind != 'W':
            self.stopping = True
            return True
        if self.cur is not None and self.cur.kind != 'W':
            self.v = 0
            self.acc = 0
        return False

    def invalidate(self):
        self.valid_to = 0

    def run(self, tlim):
        """Process every tick at or before tlim; return the instant of the
        first event (vector end, stop end, W phase end) or None."""
        jlim = tlim // self.TP
        R = self.R
        while self.jn <= jlim:
            j = self.jn
            if j % R == 0 and self.planned_at != j and j >= self.valid_to:
                self.planned_at = j
                if self.plan(j):
                    if self.valid_to == 0:
                        self.planned_at = -1
                    return j * self.TP
            cur = self.cur
            if cur is None or self.v == 0:
                if (cur is None and (not self.queue or self.inta or self.mpg)) or \
                   (cur is not None and self.inta and not self.stopping and cur.kind != 'W'):
                    self.jn = jlim + 1
                else:
                    self.jn = min((j // R + 1) * R, jlim + 1)
                continue
            nb = (j // R + 1) * R
            if self.valid_to > j:
                nb = max(nb, self.valid_to)
            end = min(nb, jlim + 1)
            c = end - j
            need = cur.n - cur.k
            v = self.v
            if need <= 0:
                self.end_vector(j * self.TP)
                return j * self.TP
            cneed = (need * self.F - self.acc + v - 1) // v
            if cneed <= c:
                te = j + cneed - 1
                self.acc += cneed * v - need * self.F
                self.adv(cur, need)
                self.jn = te + 1
                self.end_vector(te * self.TP)
                return te * self.TP
            tot = self.acc + c * v
            s = tot // self.F
            self.acc = tot - s * self.F
            if s:
                self.adv(cur, s)
            self.jn = end
        return None


# ---------------------------------------------------------------------------
# The unit: UART, dispatcher, status, EEPROM
# ---------------------------------------------------------------------------
NUM = re.compile(r'[+-]?\d+\Z')
HEX = re.compile(r'[0-9A-Fa-f]+\Z')
FLT = re.compile(r'[+-]?(\d+(\.\d*)?|\.\d+)([eE][+-]?\d+)?\Z')


def dec(s):
    if not NUM.match(s):
        raise Err(4)
    return int(s)


def hexv(s):
    if not HEX.match(s):
        raise Err(4)
    return int(s, 16)


def rng(v, lo, hi):
    if v < lo or v > hi:
        raise Err(5)
    return v


class Unit:
    def __init__(self, model, address=0, eeprom_path=None):
        self.model = model
        self.F = MODELS[model]
        self.address = address
        self.motion = Motion(self.F)
        self.eeprom_path = eeprom_path
        self.ee = bytearray(b'\xff' * 256)        # as shipped: erased (R52)
        if eeprom_path:
            try:
                with open(eeprom_path, 'rb') as f:
                    data = f.read(256)
                self.ee[:len(data)] = data
            except OSError:
                pass
        self.inputs = {0: 0xFF, 1: 0xFF, 2: 0xFF}
        self.switches = {}
        self.rate_pos = None
        self.rate = None
        self.line_baud = 115200
        self.txbuf = bytearray()
        self.restart_end = None
        self.version = 'IP114/%d x16 16.9.2018' % (self.F // 1000)
        self.reset(0, deaf=False)

    # -- reset (13.5) ----------------------------------------------------
    def reset(self, t, deaf=True, power=False):
        m = self.motion
        m.reset()
        m.cnt = [0, 0, 0, 0]
        self.st = [0] * 6
        self.st6x = 0                 # SW6-written bits that are not derived
        self.cks = False
        self.index = 0
        self.last_answer = None
        self.packet = None
        self.kept = None
        self.keepmode = False
        self.h_pending = False
        self.w_pending = False
        self.pending_frames = deque()
        self.buf = None
        self.wd_at = None
        self.spindle = 0
        self.outputs = 0xFF
        self.A = 20
        self.V = 1000
        self.B = self.F                # R13
        self.short = 512
        self.vk = False                # R27
        self.mpg_mode = '-'
        # EEPROM parameters read at reset (R54)
        ee = self.ee
        pol = ee[0x05]
        m.dirsign = [1 if (pol >> (4 + i)) & 1 else -1 for i in range(4)]
        m.aslave = ee[0x0C] if ee[0x0C] in (1, 2, 3) else 0
        m.in1 = self.inputs[1]
        m.st2 = 0
        self.outfun = {2: ee[0x01], 3: ee[0x02], 1: ee[0x03]}   # bit -> function
        self.mpg_ok = self.mpg_valid()
        if power and self.rate_pos is not None:
            hi = ee[0x0D] == 0x01
            table = [921600, 460800, 230400, 115200] if hi else [19200, 38400, 57600, 115200]
            self.rate = table[self.rate_pos]
        if deaf:
            self.restart_end = t + RESTART_NS
            start = t + RESTART_NS
        else:
            self.restart_end = None
            start = t
        if self.mpg_ok and ee[0x06] in (0x01, 0x02, 0x81, 0x82):
            self.mpg_mode = '&'        # R59
            m.mpg = True
        self.brake_at = None
        if 0x08 in self.outfun.values():
            self.brake_at = start + min(ee[0xFD], 50) * 100_000_000

    def ee_float(self, a):
        return struct.unpack('<f', bytes(self.ee[a:a + 4]))[0]

    def ee_u32(self, a):
        return struct.unpack('<I', bytes(self.ee[a:a + 4]))[0]

    def mpg_valid(self):
        ee = self.ee
        if ee[0x06] not in (0x01, 0x02, 0x81, 0x82):
            return False
        nax = 4 if ee[0x06] & 0x80 else 3

        def inr(x, lo, hi):
            return not math.isnan(x) and lo <= x <= hi
        spm = []
        for i in range(nax):
            if not inr(self.ee_float(0x10 + 4 * i), 0, 10000):
                return False
            if not inr(self.ee_float(0x20 + 4 * i), 0, 10000):
                return False
            s = self.ee_float(0x30 + 4 * i)
            if not inr(s, 1, 10000):
                return False
            spm.append(s)
        if not inr(self.ee_float(0x40), 1, 10000):
            return False
        vmax = self.ee_float(0x44)
        if not inr(vmax, 0.0, 1e9) or vmax <= 0:
            return False
        if any(vmax * s > self.F / 4 for s in spm):
            return False
        if not (1 <= self.ee_u32(0x48) <= 2000):
            return False
        mul = self.ee_float(0x60)
        if not inr(mul, 1e-9, 1e9):
            return False
        return True

    # -- status ------------------------------------------------------------
    def st6(self):
        m = self.motion
        v = self.st6x & 0x2E
        if m.stopping:
            v |= 0x01
        if m.intcom:
            v |= 0x10
        if m.run_bit():
            v |= 0x40
        if m.inta:
            v |= 0x80
        return v

    def flag(self):
        v = self.st6()
        if self.motion.held_count() >= QUEUE_CAP or self.keepmode and self.motion.held_count() >= 1:
            v |= 0x20
        else:
            v &= ~0x20
        return v

    def check_interrupts(self):
        m = self.motion
        if m.w:
            return                      # R39
        a1 = ~(self.inputs[1] ^ self.st[2]) & self.st[0] & 0xFF
        a2 = ~(self.inputs[2] ^ self.st[3]) & self.st[1] & 0xC0
        if a1 or a2:
            self.st[4] |= a1
            self.st[5] |= a2
            if not m.inta:
                m.halt()

    # -- timers --------------------------------------------------------------
    def next_timer(self):
        c = [x for x in (self.wd_at, self.restart_end, self.brake_at) if x is not None]
        return min(c) if c else None

    def on_timer(self, t):
        if self.restart_end is not None and self.restart_end <= t:
            self.restart_end = None
        if self.brake_at is not None and self.brake_at <= t:
            self.brake_at = None
            for bit, fn in self.outfun.items():
                if fn == 0x08:
                    self.outputs &= ~(1 << bit) & 0xFF
        if self.wd_at is not None and self.wd_at <= t:
            self.wd_at = None
            buf = self.buf
            self.buf = None
            if buf is not None and len(buf) >= 2 and buf[1] - 48 in (self.address, 7):
                self.answer(2)

    # -- motion events -------------------------------------------------------
    def on_motion(self, t):
        evs = self.motion.events
        self.motion.events = []
        for ev in evs:
            if ev[0] == 'stopped' and self.h_pending:
                self.h_pending = False
                self.answer(0)
            elif ev[0] == 'wdone' and self.w_pending:
                self.w_pending = False
                self.answer(ev[1])
        while self.pending_frames and not (self.h_pending or self.w_pending):
            self.execute(t, self.pending_frames.popleft())

    # -- UART ----------------------------------------------------------------
    def rate_ok(self):
        return self.rate is None or self.rate == self.line_baud

    def send(self, s):
        if self.rate_ok():
            self.txbuf += s.encode('latin-1')

    def on_rx(self, t, b):
        if self.restart_end is not None or not self.rate_ok():
            return
        if b == 0x21:
            self.buf = bytearray(b'!')
            self.wd_at = t + WATCHDOG_NS
            return
        if self.buf is None:
            return
        if b == 0x0D:
            frame = bytes(self.buf)
            self.buf = None
            self.wd_at = None
            self.frame_in(t, frame)
            return
        if b == 0x0A:
            return
        if len(self.buf) < 250:
            self.buf.append(b)

    def frame_in(self, t, frame):
        if len(frame) < 2 or frame[1] - 48 not in (self.address, 7):
            return
        if self.h_pending or self.w_pending:
            self.pending_frames.append(frame)
            return
        self.execute(t, frame)

    def answer(self, code, fields=None, packet_ok=False):
        if self.packet is not None and not packet_ok:
            return
        s = '%X' % ((8 if self.motion.inta else 0) | code)
        if fields:
            s += ',' + ','.join(fields)
        if self.cks:
            s += ',%02X' % (sum((s + ',').encode('latin-1')) & 0xFF)
        s += '\r'
        self.last_answer = s
        self.send(s)

    def execute(self, t, frame):
        addr = frame[1] - 48
        body = frame[2:].decode('latin-1')
        if self.cks:
            i = body.rfind(',')
            ok = False
            if i >= 0 and re.fullmatch(r'[0-9A-Fa-f]{2}', body[i + 1:]):
                ok = (sum(frame[:2 + i + 1]) & 0xFF) == int(body[i + 1:], 16)
            if not ok:
                if self.packet is not None:
                    self.packet['count'] += 1
                    if not self.packet['err']:
                        self.packet['err'] = 4
                    return
                self.answer(4)          # R5
                return
            body = body[:i]
        if body not in ('@', '>'):
            self.index = (self.index + 1) & 0xFF
        # packets (13.4)
        if addr != 7 and body.startswith('*'):
            if body == '*S':
                self.packet = {'count': 0, 'err': 0}
                return
            if body.startswith('*E'):
                if self.packet is None:
                    self.answer(4)
                    return
                p = self.packet
                try:
                    n = dec(body[2:])
                except Err:
                    n = -1
                code = p['err'] or (0 if n == p['count'] else 2)
                self.packet = None
                self.check_interrupts()
                self.answer(code, [str(p['count'])], packet_ok=True)
                return
        if self.packet is not None:
            p = self.packet
            p['count'] += 1
            if p['err']:
                return
            if addr == 7 or not body or body[0] not in 'CB':
                p['err'] = 3            # R11
                return
            try:
                r = self.command(t, addr, body)
                code = r[0]
            except Err as e:
                code = e.code
            self.check_interrupts()
            if code:
                p['err'] = code
            return
        try:
            r = self.command(t, addr, body)
        except Err as e:
            r = (e.code, None)
        if r is None:
            return                      # answered later (H, W) or already (J)
        self.check_interrupts()
        self.answer(r[0], r[1])

    # -- command dispatcher (13.6, 13.7) --------------------------------------
    def command(self, t, addr, body):
        m = self.motion
        if body == '?':
            return 0, [self.version]
        if body == 'Q':
            return 0, [QID]
        if body == '@':
            return 0, [str(self.index)]
        if body == '>':
            if self.last_answer is None:
                return 0, None
            self.send(self.last_answer)
            return None
        if body == 'J':
            self.answer(0)
            self.reset(t, deaf=True)
            return None
        if body.startswith('%'):
            if body == '%+':
                self.cks = True
                return 0, None
            if body == '%-':
                self.cks = False
                return 0, None
            raise Err(4)
        if body.startswith('E'):
            return self.cmd_eeprom(body)
        if addr == 7:
            if body.startswith('V'):
                v = rng(dec(body[1:]), 0, 1000)
                self.spindle = v
                if v:
                    self.outputs &= 0xFE
                else:
                    self.outputs |= 0x01
                return 0, None
            raise Err(3)
        c = body[:1]
        if c in ('L', 'C'):
            return self.cmd_vector(c, body[1:])
        if body.startswith('VL'):
            ps = body[2:].split(',')
            if len(ps) not in (3, 4):
                raise Err(4)
            vals = [dec(p) for p in ps]
            for v in vals:
                rng(v, 10, self.F)
            m.vl = vals + [0] * (4 - len(vals))
            m.invalidate()
            return 0, None
        if body == 'VK':
            self.vk = True
            return 0, None
        if body == 'VN':
            self.vk = False
            return 0, None
        if c == 'V':
            self.V = rng(dec(body[1:]), 10, self.F)
            return 0, None
        if c == 'A':
            self.A = rng(dec(body[1:]), 1, 100000)
            return 0, None
        if c == 'B':
            self.B = rng(dec(body[1:]), 10, self.F)
            return 0, None
        if c == '$':
            self.short = rng(dec(body[1:]), 1, MAXI)
            return 0, None
        if c == 'T':
            m.T = rng(dec(body[1:]), 1, 24)
            return 0, None
        if c == 'X':
            return self.cmd_exchange(body)
        if body == 'P':
            return 0, [str(m.cnt[0]), str(m.cnt[1])]
        if body == 'PF':
            return 0, [str(m.cnt[0]), str(m.cnt[1]), str(m.cnt[2])]
        if c == 'N':
            return self.cmd_null(body)
        if c == 'W':
            return self.cmd_ref(t, body)
        if c == 'Y':
            return self.cmd_mpg(body)
        if body == 'K':
            if m.moving():
                raise Err(7)
            self.kept = (list(([m.cur] if m.cur else []) + list(m.queue)),
                         self.st[4], self.st[5], m.inta, m.intcom, self.st6x)
            m.cur = None
            m.queue = deque()
            self.st[4] = self.st[5] = 0
            m.inta = m.intcom = False
            self.st6x = 0
            self.keepmode = True
            m.invalidate()
            return 0, None
        if body == 'R':
            if m.moving():
                raise Err(7)
            if self.kept is None:
                return 0, None          # R43
            q, s4, s5, inta, intcom, x = self.kept
            self.kept = None
            self.keepmode = False
            m.cur = None
            m.queue = deque(q)
            m.v = 0
            m.acc = 0
            self.st[4], self.st[5] = s4, s5
            m.inta, m.intcom = inta, intcom
            self.st6x = x
            m.invalidate()
            return 0, None
        if body == 'H':
            m.intcom = True
            if m.halt():
                self.h_pending = True
                return None
            return 0, None
        if body == 'D':
            if m.moving():
                raise Err(7)
            m.cur = None
            m.queue = deque()
            m.v = 0
            self.st[4] = self.st[5] = 0
            m.inta = m.intcom = False
            self.st6x = 0
            m.invalidate()
            return 0, None
        if body == 'G':
            if not m.inta:
                return 6, None
            if m.stopping:
                raise Err(7)
            m.inta = m.intcom = False
            self.st[4] = self.st[5] = 0
            m.invalidate()
            if m.cur is None and not m.queue:
                return 6, None
            return 0, None
        if c == 'O':
            ps = body[1:].split(',')
            if len(ps) != 2:
                raise Err(4)
            port = dec(ps[0])
            val = hexv(ps[1])
            rng(port, 0, 0)
            rng(val, 0, 0xFF)
            self.outputs = val
            return 0, None
        if c == 'I':
            port = dec(body[1:])
            rng(port, 1, 2)
            if port == 1:
                return 0, ['%02X' % self.inputs[1]]
            return 0, ['%02X' % ((self.inputs[2] & 0xC0) | 0x3F)]
        if body.startswith('SR'):
            n = rng(dec(body[2:]), 0, 6)
            return 0, ['%02X' % (self.st6() if n == 6 else self.st[n])]
        if body.startswith('SW'):
            ps = body[2:].split(',')
            if len(ps) != 2:
                raise Err(4)
            n = dec(ps[0])
            x = hexv(ps[1])
            rng(n, 0, 6)
            rng(x, 0, 0xFF)
            if n < 6:
                self.st[n] = x
                if n == 2:
                    m.st2 = x
                return 0, None
            self.st6x = x & 0x2E
            m.intcom = bool(x & 0x10)
            if x & 0x80 and not m.inta:
                m.halt()
            elif not x & 0x80 and m.inta and not m.stopping:
                m.inta = False
            m.invalidate()
            return 0, None
        if body == 'F':
            return 0, ['%02X' % self.flag()]
        raise Err(3)

    def cmd_vector(self, c, rest):
        m = self.motion
        ps = rest.split(',')
        if len(ps) not in (3, 4):
            raise Err(4)
        d = [dec(p) for p in ps]
        for x in d:
            rng(x, -MAXI, MAXI)
        d += [0] * (4 - len(d))
        if m.aslave:
            d[3] = 0                    # R57
        if self.mpg_mode != '-' or m.w:
            raise Err(7)
        if c == 'L':
            if m.cur is not None or m.queue:
                raise Err(1)            # R17
        else:
            if self.keepmode or m.held_count() >= QUEUE_CAP:
                raise Err(1)
        vec = Vec(c, d, self.V, self.B, self.A, max(abs(x) for x in d) < self.short, self.vk)
        m.queue.append(vec)
        m.invalidate()
        return 0, None

    def cmd_exchange(self, body):
        m = self.motion
        vecs = ([m.cur] if m.cur is not None and m.cur.kind != 'W' else []) + list(m.queue)
        if body == 'XA':
            for v in vecs:
                v.vcmd = self.V
        elif body == 'XU':
            for v in vecs:
                v.vcmd = min(self.F, v.vcmd + v.vcmd // 16)
        elif body == 'XD':
            for v in vecs:
                v.vcmd = max(10, v.vcmd - v.vcmd // 16)
        elif body.startswith('XM'):
            n = rng(dec(body[2:]), 1, 1000)
            for v in vecs:
                v.vcmd = self.V
            m.xm = n
        else:
            raise Err(3)
        m.invalidate()
        return 0, None

    def cmd_null(self, body):
        m = self.motion
        if body == 'N':
            if m.run_bit():
                raise Err(7)
            m.cnt = [0, 0, 0, 0]        # R33
            return 0, None
        ax = AXES.find(body[1].upper())
        if ax < 0:
            raise Err(4)
        n = rng(dec(body[2:]), -MAXI, MAXI)
        if m.run_bit():
            raise Err(7)
        m.cnt[ax] = n
        return 0, None

    def cmd_ref(self, t, body):
        m = self.motion
        if len(body) < 2:
            raise Err(4)
        ax = AXES.find(body[1].upper())
        if ax < 0:
            raise Err(4)
        ps = body[2:].split(',')
        if len(ps) != 4:
            raise Err(4)
        n2, n3, n4, n5 = [dec(p) for p in ps]
        if n2 == 0:
            raise Err(5)
        rng(n2, -MAXI, MAXI)
        rng(n3, 10, self.F)
        rng(n4, 1, MAXI)
        rng(n5, 10, self.F)
        if m.run_bit():
            raise Err(7)
        m.start_w(ax, n2, n3, n4, n5, self.switches.get(ax))
        self.w_pending = True
        return None

    def cmd_mpg(self, body):
        m = self.motion
        p = body[1:]
        if p not in ('+', '&', '-'):
            raise Err(5)
        if p != '-':
            if not self.mpg_ok:
                raise Err(5)
            if m.cur is not None or m.queue or m.w:
                raise Err(7)
            m.mpg = True
        else:
            m.mpg = False
        self.mpg_mode = p
        m.invalidate()
        return 0, [body]

    def cmd_eeprom(self, body):
        for pre, size, kind in (('EFR', 4, 'f'), ('EUR', 4, 'u'), ('ER', 1, 'b'),
                                ('EFW', 4, 'F'), ('EUW', 4, 'U'), ('EW', 1, 'B')):
            if body.startswith(pre):
                break
        else:
            raise Err(3)
        rest = body[len(pre):]
        if kind in 'fub':
            a = rng(hexv(rest), 0, 0xFF)
            if a + size > 256:
                raise Err(5)
            if kind == 'b':
                return 0, ['%02X' % self.ee[a]]
            if kind == 'u':
                return 0, [str(self.ee_u32(a))]
            return 0, [fmt_f32(self.ee_float(a))]
        ps = rest.split(',')
        if len(ps) != 2:
            raise Err(4)
        a = rng(hexv(ps[0]), 0, 0xFF)
        if a + size > 256:
            raise Err(5)
        if kind == 'B':
            x = rng(hexv(ps[1]), 0, 0xFF)
            data = bytes([x])
        elif kind == 'U':
            x = rng(dec(ps[1]), 0, 0xFFFFFFFF)
            data = struct.pack('<I', x)
        else:
            if not FLT.match(ps[1]):
                raise Err(4)
            x = float(ps[1])
            try:
                data = struct.pack('<f', x)
            except OverflowError:
                raise Err(5)
        self.ee[a:a + size] = data
        if self.eeprom_path:
            try:
                with open(self.eeprom_path, 'wb') as f:
                    f.write(self.ee)
            except OSError:
                pass
        return 0, None

    # -- rig ---------------------------------------------------------------
    def state(self, now):
        m = self.motion
        return {
            'profile': self.model,
            'addresses': [self.address, 7],
            'time_ns': now,
            'position': list(m.cnt),
            'physical': list(m.phys),
            'excursion': [list(e) for e in m.exc],
            'status': ['%02X' % x for x in self.st] + ['%02X' % self.st6()],
            'outputs': '%02X' % self.outputs,
            'spindle': self.spindle,
            'rate_position': self.rate_pos,
            'rate': self.rate,
            'inputs': {str(k): '%02X' % v for k, v in self.inputs.items()},
            'queue': m.held_count(),
            'index': self.index,
            'checksums': self.cks,
            'modal': {'V': self.V, 'A': self.A, 'B': self.B, '$': self.short,
                      'T': m.T, 'VK': self.vk, 'VL': m.vl, 'XM': m.xm},
            'mpg': self.mpg_mode,
            'kept': self.kept is not None,
            'packet_open': self.packet is not None,
            'restarting': self.restart_end is not None,
        }


# ---------------------------------------------------------------------------
# Co-simulation engine (given/cosim.md)
# ---------------------------------------------------------------------------
class CoSim:
    def __init__(self, unit, out=sys.stdout):
        self.u = unit
        self.now = 0
        self.baud = 115200
        self.b = round(10 * 10**9 / self.baud)
        self.rxq = deque()              # (instant, byte) to the unit
        self.txq = deque()              # bytes waiting in the unit's transmitter
        self.inflight = None            # (instant complete, byte)
        self.out = out

    def pump(self):
        u = self.u
        if u.txbuf:
            self.txq.extend(u.txbuf)
            u.txbuf.clear()
        if self.inflight is None and self.txq:
            self.inflight = (self.now + self.b, self.txq.popleft())

    def advance(self, limit, cr_stop):
        out = []
        u = self.u
        INF = BIG
        while True:
            t_rx = self.rxq[0][0] if self.rxq else INF
            t_tx = self.inflight[0] if self.inflight else INF
            tt = u.next_timer()
            t_tm = tt if tt is not None else INF
            t_other = min(t_rx, t_tx, t_tm)
            tm = min(limit, t_other)
            ev = u.motion.run(tm)
            if ev is not None:
                self.now = max(self.now, ev)
                u.on_motion(self.now)
                self.pump()
                continue
            if t_other > limit:
                self.now = limit
                return out, False
            self.now = t_other
            if t_tm == t_other:
                u.on_timer(self.now)
                self.pump()
                continue
            if t_rx == t_other:
                _, byte = self.rxq.popleft()
                u.on_rx(self.now, byte)
                self.pump()
                continue
            t, byte = self.inflight
            self.inflight = None
            out.append((t, byte))
            self.pump()
            if cr_stop and byte == 0x0D:
                return out, True

    def next_event(self):
        c = []
        if self.rxq:
            c.append(self.rxq[0][0])
        if self.inflight:
            c.append(self.inflight[0])
        tt = self.u.next_timer()
        if tt is not None:
            c.append(tt)
        lim = min(c) if c else self.now + 10**15
        m = copy.deepcopy(self.u.motion)
        ev = m.run(lim)
        if ev is not None:
            c.append(ev)
        return min(c) if c else None

    # -- protocol --------------------------------------------------------
    def emit(self, s):
        self.out.write(s + '\n')

    def rx_lines(self, out):
        for t, byte in out:
            self.emit('rx %d %02X' % (t, byte))

    @staticmethod
    def num(s):
        if not re.fullmatch(r'[0-9]{1,20}', s):
            raise ValueError('bad number %r' % s)
        return int(s)

    def handle(self, line):
        w = line.split()
        if not w:
            return True
        cmd = w[0]
        args = w[1:]
        if args and args[-1].startswith('@') and cmd in ('in', 'switch', 'state', 'power-on', 'rate'):
            a = args.pop()
            if a[1:] != str(self.u.address):
                raise ValueError('no unit at address %s' % a[1:])
        if cmd in ('quit', 'exit'):
            return False
        if cmd == 'tx':
            if len(args) not in (1, 2):
                raise ValueError('usage: tx HEX [T]')
            h = args[0]
            if len(h) % 2 or not re.fullmatch(r'[0-9A-Fa-f]*', h):
                raise ValueError('bad hex')
            data = bytes.fromhex(h)
            end = self.now + len(data) * self.b
            T = None
            if len(args) == 2:
                T = self.num(args[1])
                if T < end:
                    raise ValueError('T before the end of the bytes')
            for i, byte in enumerate(data):
                self.rxq.append((self.now + (i + 1) * self.b, byte))
            out, _ = self.advance(end, False)
            if T is not None and not any(b == 0x0D for _, b in out):
                o2, _ = self.advance(T, True)
                out += o2
            self.rx_lines(out)
            self.emit('now %d' % self.now)
        elif cmd == 'until':
            if len(args) != 1:
                raise ValueError('usage: until T')
            T = self.num(args[0])
            if T < self.now:
                raise ValueError('until before now')
            out, _ = self.advance(T, True)
            self.rx_lines(out)
            self.emit('now %d' % self.now)
        elif cmd == 'next':
            if args:
                raise ValueError('usage: next')
            t = self.next_event()
            self.emit('next none' if t is None else 'next %d' % t)
        elif cmd == 'baud':
            if len(args) != 1:
                raise ValueError('usage: baud N')
            n = self.num(args[0])
            if n <= 0:
                raise ValueError('bad baud')
            self.baud = n
            self.b = round(10 * 10**9 / n)
            self.u.line_baud = n
            self.emit('ok')
        elif cmd == 'in':
            if len(args) != 2 or args[0] not in ('0', '1', '2') or \
               not re.fullmatch(r'[0-9A-Fa-f]{2}', args[1]):
                raise ValueError('usage: in PORT XX')
            self.advance(self.now, False)
            p = int(args[0])
            self.u.inputs[p] = int(args[1], 16)
            self.u.motion.in1 = self.u.inputs[1]
            self.u.motion.invalidate()
            self.u.check_interrupts()
            self.emit('ok')
        elif cmd == 'switch':
            if len(args) != 2 or args[0].upper() not in AXES or len(args[0]) != 1:
                raise ValueError('usage: switch AXIS POS|none')
            ax = AXES.index(args[0].upper())
            if args[1] == 'none':
                self.u.switches.pop(ax, None)
            else:
                if not re.fullmatch(r'[+-]?[0-9]{1,20}', args[1]):
                    raise ValueError('bad position')
                self.u.switches[ax] = int(args[1])
            self.emit('ok')
        elif cmd == 'rate':
            if len(args) != 1:
                raise ValueError('usage: rate POS|none')
            if args[0] == 'none':
                self.u.rate_pos = None
            else:
                p = self.num(args[0])
                if p > 3:
                    raise ValueError('rate position 0..3')
                self.u.rate_pos = p
            self.emit('ok')
        elif cmd == 'power-on':
            if args:
                raise ValueError('usage: power-on')
            self.advance(self.now, False)
            u = self.u
            if u.rate_pos is None:
                u.rate = None
            u.reset(self.now, deaf=True, power=True)
            self.emit('ok')
        elif cmd == 'state':
            if args:
                raise ValueError('usage: state')
            self.emit(json.dumps(self.u.state(self.now)))
        elif cmd == 'help':
            self.emit('commands: tx HEX [T] | until T | next | baud N | in PORT XX | '
                      'switch AXIS POS|none | rate POS|none | power-on | state | quit')
        else:
            raise ValueError('unknown command %r' % cmd)
        return True

    def serve(self, inp):
        self.emit('cosim 1')
        self.out.flush()
        for raw in inp:
            line = raw.rstrip('\n').rstrip('\r')
            if not line.strip():
                continue
            try:
                if not self.handle(line):
                    self.out.flush()
                    return
            except ValueError as e:
                self.emit('error: %s' % e)
            except Exception as e:      # never die mid-session: report and go on
                import traceback
                traceback.print_exc(file=sys.stderr)
                self.emit('error: internal: %s' % e)
            self.out.flush()


def main():
    ap = argparse.ArgumentParser(description='GVE114 interpolator simulator')
    ap.add_argument('--model', default='GVE114-500', choices=sorted(MODELS))
    ap.add_argument('--cosim', action='store_true', help='speak given/cosim.md on stdin/stdout')
    ap.add_argument('--address', type=int, default=0, choices=range(0, 7))
    ap.add_argument('--eeprom', help='file holding the 256-byte EEPROM image (kept across runs)')
    a = ap.parse_args()
    if not a.cosim:
        ap.error('only --cosim is implemented (virtual time on stdin/stdout)')
    unit = Unit(a.model, a.address, a.eeprom)
    CoSim(unit).serve(sys.stdin)


if __name__ == '__main__':
    main()
