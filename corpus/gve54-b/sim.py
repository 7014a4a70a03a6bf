#!/usr/bin/env python3
"""GVE54 (firmware Ip54v3) simulator -- one unit, virtual time, co-simulation.

Written from the vendor's instruction-set document alone (given/GVE54-manual.txt).
Every place where the document had to be interpreted is numbered in READINGS.md
and referenced here as [R<n>].

Structure (as firmware would be):
  * UART RX "interrupt": rx_byte() -- framing state machine, frame buffer, watchdog.
  * main loop: execute() -- walks the frame buffer character by character.
  * timer compare "interrupt": step_isr() -- one major-axis step per compare,
    Bresenham for the minor axes, integer ramp in v^2 (v^2 +- 2A per step),
    next compare value in timer ticks (F_CPU/8).
  * UART TX: a FIFO of bytes, one every 10 bit times.
The co-simulation layer (class Cosim) merges these with the host's bytes.
"""
import sys
import json
import copy
from math import isqrt

F_CPU = 15_667_200              # crystal (115200*8*17)
TIMER_HZ = F_CPU // 8           # step timer, prescaler 8 -> 1 958 400 Hz [R28]
NS_PER_S = 1_000_000_000

QUEUE_SIZE = 96                 # vectors held, the executed one included [R8]
FRAME_MAX = 32                  # frame buffer (chars after the address) [R36]
WATCHDOG_NS = 100_000_000       # a frame must be complete 100 ms after its '!' [R3]
RESTART_NS = 2_000_000_000      # "cca po 2s"
VERSION = "Ip54v3 21.12.2007"   # [R31]
CPU_ID = "21120701"             # [R32]
RATE_POSITIONS = [115200, 57600, 38400, 19200, 9600]   # [R40]

# ST6 bits
ST6_STOP = 0x01
ST6_FREE = 0x02
ST6_INTCOM = 0x10
ST6_FULL = 0x20                 # only in F
ST6_RUN = 0x40
ST6_INTA = 0x80

MODE_P = {'2': 8, '4': 4, '8': 2, 'F': 1}   # counter units per pulse


def tick_to_ns(t):
    return -((-t * 8 * NS_PER_S) // F_CPU)          # ceil


def ns_to_tick(ns):
    return -((-ns * F_CPU) // (8 * NS_PER_S))       # ceil


class Err(Exception):
    def __init__(self, code):
        Exception.__init__(self, code)
        self.code = code


class Vector:
    __slots__ = ('kind', 'd', 'n', 'done', 'acc', 'v', 'a', 'b', 'short', 'dwell_ns')

    def __init__(self, kind, d, v, a, b, short_lim, dwell_ms):
        self.kind = kind
        self.d = d
        self.n = max(abs(x) for x in d)              # major-axis steps [R12]
        self.done = 0
        self.acc = [self.n // 2] * 3                  # Bresenham accumulators
        self.v = v                                    # V, pulses/s
        self.a = a                                    # pulses/s^2
        self.b = b                                    # B, pulses/s
        self.short = self.n < short_lim               # [R13]
        self.dwell_ns = dwell_ms * 1_000_000

    def target(self):
        return min(self.v, self.b) if self.short else self.v     # [R14]

    def remaining(self):
        return self.n - self.done


class Cur:
    """Character cursor over the received frame (as a MCU walks its buffer)."""

    def __init__(self, buf):
        self.buf = buf
        self.i = 0

    def peek(self):
        return self.buf[self.i] if self.i < len(self.buf) else None

    def get(self):
        c = self.peek()
        if c is not None:
            self.i += 1
        return c

    def end(self):
        if self.i != len(self.buf):
            raise Err(4)

    def comma(self):
        if self.get() != ',':
            raise Err(4)

    def dec(self):
        neg = False
        if self.peek() == '-':
            self.get()
            neg = True
        val = 0
        digits = 0
        while True:
            c = self.peek()
            if c is None or not ('0' <= c <= '9'):
                break
            self.get()
            digits += 1
            val = min(val * 10 + ord(c) - 48, 9_999_999)   # saturating accumulator
        if not digits:
            raise Err(4)
        return -val if neg else val

    def hex(self):
        val = 0
        digits = 0
        while True:
            c = self.peek()
            if c is None:
                break
            if '0' <= c <= '9':
                d = ord(c) - 48
            elif 'A' <= c <= 'F':
                d = ord(c) - 55
            elif 'a' <= c <= 'f':
                d = ord(c) - 87
            else:
                break
            self.get()
            digits += 1
            val = min(val * 16 + d, 0xFFFFF)
        if not digits:
            raise Err(4)
        return val


def rng(x, lo, hi):
    if not lo <= x <= hi:
        raise Err(5)
    return x


class Unit:
    # motion states
    IDLE, DWELL, RUN = 0, 1, 2

    def __init__(self, address='0'):
        self.address = address
        self.eeprom = bytearray([0xFF] * 256)        # [R30]
        self.inputs = [0xFF, 0xFF, 0xFF]             # [R25]
        self.phys = [0, 0, 0]
        self.exc = [[0, 0], [0, 0], [0, 0]]
        self.rate_position = None
        self.rate = None          # unit's rate (None: the line's)
        self.line_baud = 115200
        self.bt = round(10 * NS_PER_S / 115200)
        # TX
        self.tx_fifo = []
        self.tx_cur = None        # (complete_ns, byte)
        self.reset_after_tx = False
        self.deaf_until = None
        self.jumping = False
        self.reset_state(0)
        self.deaf_until = None    # the simulator starts with the unit ready

    # ------------------------------------------------------------------ reset
    def reset_state(self, t):
        self.st = [0, 0, 0, 0, 0, 0]
        self.st6 = 0
        self.current = 'D'
        self.P = 1
        self.mode = 'F'
        self.A = 20
        self.V = 1000
        self.short = 512
        self.B = 50000
        self.T = 0                                   # [R10]
        self.pos = [0, 0, 0]
        self.outputs = 0xFF
        self.queue = []
        self.jcache = None
        self.kept = None
        self.index = 0
        self.last_answer = None
        self.mstate = Unit.IDLE
        self.braking = False
        self.h_pending = False
        self.v2 = 0
        self.v2_next = 0
        self.step_tick = 0
        self.step_fp = 0
        self.step_t = None
        self.dwell_t = None
        self.last_stop = -10 ** 18
        self.rx_state = 'idle'
        self.rx_buf = []
        self.rx_over = False
        self.wd_t = None
        self.jumping = False
        self.reset_after_tx = False
        self.deaf_until = t + RESTART_NS

    def power_on(self, t):
        self.reset_state(t)
        if self.rate_position is not None:
            self.rate = RATE_POSITIONS[self.rate_position]
        else:
            self.rate = None

    # ------------------------------------------------------------------ TX
    def send(self, t, text):
        for ch in text.encode('latin-1'):
            if self.tx_cur is None:
                self.tx_cur = (t + self.bt, ch)
            else:
                self.tx_fifo.append(ch)

    def answer(self, t, code, params=(), store=True):
        code &= 7
        s = '%X' % (code | (8 if self.st6 & ST6_INTA else 0))
        for p in params:
            s += ',' + p
        s += '\r'
        if store:
            self.last_answer = s
        if code == 0:
            self.index = (self.index + 1) & 0xFF      # [R33]
        self.send(t, s)

    # ------------------------------------------------------------------ events
    def next_event(self):
        best = None
        for t, k in ((self.deaf_until, 'reset'), (self.wd_t, 'wd'), (self.dwell_t, 'dwell'),
                     (self.step_t, 'step'), (self.tx_cur[0] if self.tx_cur else None, 'tx')):
            if t is not None and (best is None or t < best[0]):
                best = (t, k)
        return best

    def run_event(self, t, kind):
        """Returns (reportable, byte_sent_or_None)."""
        if kind == 'reset':
            self.deaf_until = None
            return True, None
        if kind == 'wd':
            self.wd_t = None
            st = self.rx_state
            self.rx_state = 'idle'
            if st == 'body':
                self.answer(t, 2, store=False)        # [R4]
            return True, None
        if kind == 'dwell':
            self.dwell_t = None
            self.mstate = Unit.IDLE
            return self.begin(t), None
        if kind == 'step':
            return self.step_isr(t), None
        if kind == 'tx':
            when, ch = self.tx_cur
            self.tx_cur = None
            if self.tx_fifo:
                self.tx_cur = (when + self.bt, self.tx_fifo.pop(0))
            elif self.reset_after_tx:
                self.reset_state(t)                   # J: the jump happens now [R35]
            return True, ch
        raise AssertionError(kind)

    # ------------------------------------------------------------------ RX ISR
    def rx_byte(self, t, ch):
        if self.deaf_until is not None or self.jumping:
            return
        if self.rate is not None and self.rate != self.line_baud:
            return                                     # framing errors [R40]
        if self.h_pending:
            return                                     # main loop busy in HALT [R21]
        c = chr(ch)
        if c == '!':                                   # always (re)starts a frame [R2]
            self.rx_state = 'addr'
            self.rx_buf = []
            self.rx_over = False
            self.wd_t = t + WATCHDOG_NS
            return
        st = self.rx_state
        if st == 'idle':
            return
        if st == 'addr':
            if c == '\r':
                self.rx_state = 'idle'
                self.wd_t = None
            elif c == self.address:
                self.rx_state = 'body'
            else:
                self.rx_state = 'skip'
            return
        if st == 'skip':
            if c == '\r':
                self.rx_state = 'idle'
                self.wd_t = None
            return
        # body
        if c == '\r':
            self.rx_state = 'idle'
            self.wd_t = None
            buf = ''.join(self.rx_buf)
            if self.rx_over:
                self.answer(t, 4)
                return
            self.execute(t, buf)
            return
        if len(self.rx_buf) < FRAME_MAX:
            self.rx_buf.append(c)
        else:
            self.rx_over = True

    # ------------------------------------------------------------------ status
    def running(self):
        """'za chodu': vectors being processed and not held, or a stop ramp [R16]."""
        return self.mstate != Unit.IDLE or self.braking

    def sr6(self):
        v = self.st6 & ~(ST6_RUN | ST6_FULL)
        if self.queue:
            v |= ST6_RUN
        return v

    def flags(self):
        v = self.sr6()
        if len(self.queue) >= QUEUE_SIZE:
            v |= ST6_FULL
        return v

    def poll_interrupts(self, t):
        """Level-sensitive user interrupts [R23]."""
        a0 = ~(self.inputs[1] ^ self.st[2]) & self.st[0] & 0xFF
        a1 = ~(self.inputs[2] ^ self.st[3]) & self.st[1] & 0xFF
        if a0 or a1:
            self.st[4] |= a0
            self.st[5] |= a1
            self.request_stop(t)

    def request_stop(self, t):
        self.st6 |= ST6_INTA
        if self.mstate == Unit.RUN:
            if not self.braking:
                self.braking = True
                self.st6 |= ST6_STOP                   # [R18]
        elif self.mstate == Unit.DWELL:
            self.mstate = Unit.IDLE
            self.dwell_t = None

    # ------------------------------------------------------------------ motion
    def invalidate(self):
        self.jcache = None

    def junction2(self, i):
        """Largest v^2 at the end of queue[i] (look-ahead over the queue) [R15]."""
        if self.jcache is None:
            q = self.queue
            j = [0] * len(q)
            for k in range(len(q) - 2, -1, -1):
                w = q[k + 1]
                if w.kind != 'C':
                    j[k] = 0
                else:
                    reach = j[k + 1] + 2 * w.a * w.remaining()
                    j[k] = min(q[k].b ** 2, q[k].target() ** 2, w.target() ** 2, reach)
            self.jcache = j
        return self.jcache[i]

    def try_start(self, t):
        if (self.mstate != Unit.IDLE or self.deaf_until is not None or self.jumping
                or (self.st6 & ST6_INTA) or not self.queue):
            return False
        v = self.queue[0]
        if v.kind == 'L' and v.done == 0:            # dwell before a non-continuing vector [R9]
            due = self.last_stop + v.dwell_ns
            if due > t:
                self.mstate = Unit.DWELL
                self.dwell_t = due
                return False
        return self.begin(t)

    def begin(self, t):
        v = self.queue[0]
        if v.remaining() == 0:                        # L0,0,0 / C0,0,0: ends at once [R7]
            self.queue.pop(0)
            self.invalidate()
            self.last_stop = t
            self.try_start(t)
            return True
        self.mstate = Unit.RUN
        self.v2 = 0
        self.step_fp = ns_to_tick(t) << 16
        self.schedule()
        return False

    def schedule(self):
        v = self.queue[0]
        a2 = 2 * v.a
        allow = self.junction2(0) + a2 * (v.remaining() - 1)
        if self.braking:
            cand = self.v2 - a2
        else:
            vt2 = v.target() ** 2
            if self.v2 < vt2:
                cand = min(self.v2 + a2, vt2)
            else:
                cand = max(self.v2 - a2, vt2)
        nv2 = max(0, min(cand, allow))
        s = isqrt(self.v2) + isqrt(nv2)
        if s == 0:
            s = max(1, isqrt(v.a))                    # single step from rest to rest
        # dt = 2/(v0+v1) in timer ticks, 16 fractional bits carried from step to
        # step so that the mean rate is exact [R28]
        self.v2_next = nv2
        self.step_fp += max(1 << 16, ((2 * TIMER_HZ << 16) + s // 2) // s)
        self.step_tick = self.step_fp >> 16
        self.step_t = tick_to_ns(self.step_tick)

    def step_isr(self, t):
        v = self.queue[0]
        for k in range(3):                            # Bresenham, one major step
            dk = v.d[k]
            if dk == 0:
                continue
            v.acc[k] += abs(dk)
            if v.acc[k] >= v.n:
                v.acc[k] -= v.n
                inc = self.P if dk > 0 else -self.P   # [R26]
                self.pos[k] += inc
                self.phys[k] += inc
                e = self.exc[k]
                if self.phys[k] < e[0]:
                    e[0] = self.phys[k]
                if self.phys[k] > e[1]:
                    e[1] = self.phys[k]
        v.done += 1
        self.v2 = self.v2_next
        rep = False
        if v.remaining() == 0:
            self.queue.pop(0)
            self.invalidate()
            rep = True
            while self.v2 > 0 and self.queue and self.queue[0].kind == 'C' \
                    and self.queue[0].remaining() == 0:
                self.queue.pop(0)                     # zero-length C passed through
                self.invalidate()
            if self.v2 > 0 and self.queue and self.queue[0].kind == 'C':
                if self.braking and self.v2 <= 2 * self.queue[0].a:
                    self.come_to_rest(t)              # stop ramp ends at the junction
                    return True
                self.schedule()
                return rep
            self.come_to_rest(t)
            return True
        if self.braking and self.v2 <= 2 * v.a:
            self.come_to_rest(t)
            return True
        self.schedule()
        return rep

    def come_to_rest(self, t):
        self.mstate = Unit.IDLE
        self.step_t = None
        self.v2 = 0
        self.last_stop = t
        if self.braking:
            self.braking = False
            self.st6 &= ~ST6_STOP
        if self.h_pending:
            self.h_pending = False
            self.answer(t, 0)                         # HALT answers now [R20]
        self.try_start(t)

    def halt_now(self):
        """Pulses stop at once (J, power-on)."""
        self.mstate = Unit.IDLE
        self.step_t = None
        self.dwell_t = None
        self.braking = False
        self.v2 = 0

    # ------------------------------------------------------------------ commands
    def execute(self, t, buf):
        cur = Cur(buf)
        c = cur.get()
        try:
            h = self.DISPATCH.get(c)
            if h is None:
                raise Err(3)
            res = h(self, t, cur)
        except Err as e:
            self.answer(t, e.code)
            return
        if res is None:
            return                                    # answer later (H) or none
        code, params = res
        self.answer(t, code, params)

    def c_vector(self, kind, t, cur):
        x = cur.dec(); cur.comma()
        y = cur.dec(); cur.comma()
        z = cur.dec(); cur.end()
        for q in (x, y, z):
            rng(q, -65535, 65535)
        if kind == 'L':
            if self.queue:                            # L waits for the queue to finish [R6]
                return 1, ()
        elif len(self.queue) >= QUEUE_SIZE:
            return 1, ()
        self.queue.append(Vector(kind, (x, y, z), self.V, self.A * 1000, self.B,
                                 self.short, self.T))
        self.invalidate()
        self.try_start(t)
        return 0, ()

    def c_L(self, t, cur):
        return self.c_vector('L', t, cur)

    def c_C(self, t, cur):
        return self.c_vector('C', t, cur)

    def c_T(self, t, cur):
        n = cur.dec(); cur.end()
        self.T = rng(n, 1, 24)
        return 0, ()

    def c_V(self, t, cur):
        n = cur.dec(); cur.end()
        self.V = rng(n, 40, 50000)
        return 0, ()

    def c_B(self, t, cur):
        n = cur.dec(); cur.end()
        self.B = rng(n, 40, 50000)
        return 0, ()

    def c_S(self, t, cur):                            # $
        n = cur.dec(); cur.end()
        self.short = rng(n, 1, 65535)
        return 0, ()

    def c_A(self, t, cur):
        n = cur.dec(); cur.end()
        self.A = rng(n, 1, 255)                       # [R11]
        return 0, ()

    def c_K(self, t, cur):
        cur.end()
        if self.running():
            return 7, ()
        self.kept = (copy.deepcopy(self.queue), self.st[4], self.st[5], self.st6)
        self.queue = []
        self.invalidate()
        self.st[4] = self.st[5] = 0
        self.st6 = 0
        self.poll_interrupts(t)
        return 0, ()

    def c_R(self, t, cur):
        cur.end()
        if self.running():
            return 7, ()
        if self.kept is not None:                     # [R17]
            q, s4, s5, s6 = self.kept
            self.kept = None
            self.queue = q
            self.invalidate()
            self.st[4], self.st[5] = s4, s5
            self.st6 = s6 & ~(ST6_RUN | ST6_STOP)
            self.poll_interrupts(t)
            self.try_start(t)
        return 0, ()

    def c_H(self, t, cur):
        cur.end()
        self.st6 |= ST6_INTCOM
        self.request_stop(t)
        if self.mstate == Unit.RUN:
            self.h_pending = True
            return None
        return 0, ()

    def c_D(self, t, cur):
        cur.end()
        if self.running():
            return 7, ()
        self.queue = []
        self.invalidate()
        self.st[4] = self.st[5] = 0
        self.st6 = 0
        self.poll_interrupts(t)
        return 0, ()

    def c_X(self, t, cur):
        s = cur.get()
        if s not in ('A', 'U', 'D'):
            raise Err(3)
        cur.end()
        for v in self.queue:                          # [R19]
            if s == 'A':
                v.v = self.V
                v.a = self.A * 1000
            elif s == 'U':
                v.v = min(50000, v.v + v.v // 16)
                v.a = v.a + v.a // 16
            else:
                v.v = max(40, v.v - v.v // 16)
                v.a = max(1000, v.a - v.a // 16)
        self.invalidate()
        return 0, ()

    def c_G(self, t, cur):
        cur.end()
        if self.braking:
            return 7, ()                              # [R22]
        if not self.st6 & ST6_INTA:
            return 6, ()
        self.st6 &= ~(ST6_INTA | ST6_INTCOM)
        self.st[4] = self.st[5] = 0
        self.poll_interrupts(t)
        if not self.queue:
            return 6, ()
        self.try_start(t)
        return 0, ()

    def c_P(self, t, cur):
        if cur.peek() == 'F':
            cur.get()
            cur.end()
            return 0, tuple(str(p) for p in self.pos)
        cur.end()
        return 0, (str(self.pos[0]), str(self.pos[1]))

    def c_N(self, t, cur):
        cur.end()
        if self.queue:                                # "pri RUN=1"
            return 7, ()
        self.pos = [0, 0, 0]
        return 0, ()

    def c_E(self, t, cur):
        s = cur.get()
        if s == 'R':
            n = cur.hex(); cur.end()
            rng(n, 0, 0xFF)
            return 0, ('%02X' % self.eeprom[n],)
        if s == 'W':
            n = cur.hex(); cur.comma()
            x = cur.hex(); cur.end()
            rng(n, 0, 0xFF)
            rng(x, 0, 0xFF)
            self.eeprom[n] = x
            return 0, ()
        raise Err(3)

    def c_M(self, t, cur):
        m = cur.get()
        if m is None:
            raise Err(4)
        cur.end()
        if m not in ('U', 'D', '2', '4', '8', 'F'):
            raise Err(5)
        if self.running():
            return 7, ()
        if m in ('U', 'D'):
            self.current = m
        else:
            self.mode = m
            self.P = MODE_P[m]
        return 0, ()

    def c_O(self, t, cur):
        p = cur.hex(); cur.comma()
        x = cur.hex(); cur.end()
        rng(p, 0, 0)
        self.outputs = rng(x, 0, 0xFF)
        return 0, ()

    def c_I(self, t, cur):
        p = cur.hex(); cur.end()
        rng(p, 0, 2)
        return 0, ('%02X' % self.inputs[p],)

    def c_Sx(self, t, cur):
        s = cur.get()
        if s == 'R':
            n = cur.hex(); cur.end()
            rng(n, 0, 6)
            v = self.sr6() if n == 6 else self.st[n]
            return 0, ('%02X' % v,)
        if s == 'W':
            n = cur.hex(); cur.comma()
            x = cur.hex(); cur.end()
            rng(n, 0, 6)
            rng(x, 0, 0xFF)
            if n == 6:                                # [R24]
                was = self.st6
                self.st6 = (x & ~(ST6_RUN | ST6_FULL)) | (self.st6 & ST6_STOP if self.braking else 0)
                if self.st6 & ST6_INTA and not was & ST6_INTA:
                    self.request_stop(t)
                elif not self.st6 & ST6_INTA:
                    self.try_start(t)
            else:
                self.st[n] = x
                self.poll_interrupts(t)
            return 0, ()
        raise Err(3)

    def c_F(self, t, cur):
        cur.end()
        return 0, ('%02X' % self.flags(),)

    def c_index(self, t, cur):
        cur.end()
        s = '%X' % (8 if self.st6 & ST6_INTA else 0) + ',%02X\r' % self.index
        self.last_answer = s
        self.send(t, s)
        return None

    def c_repeat(self, t, cur):
        try:
            cur.end()
        except Err:
            self.send(t, '%X\r' % (4 | (8 if self.st6 & ST6_INTA else 0)))
            return None
        if self.last_answer is None:                  # [R34]
            self.send(t, '%X\r' % (3 | (8 if self.st6 & ST6_INTA else 0)))
        else:
            self.send(t, self.last_answer)
        return None

    def c_J(self, t, cur):
        cur.end()
        self.halt_now()
        self.jumping = True
        self.reset_after_tx = True
        self.answer(t, 0)
        return None

    def c_ver(self, t, cur):
        cur.end()
        return 0, (VERSION,)

    def c_Q(self, t, cur):
        cur.end()
        return 0, (CPU_ID,)

    DISPATCH = {
        'L': c_L, 'C': c_C, 'T': c_T, 'V': c_V, 'B': c_B, '$': c_S, 'A': c_A,
        'K': c_K, 'R': c_R, 'H': c_H, 'D': c_D, 'X': c_X, 'G': c_G, 'P': c_P,
        'N': c_N, 'E': c_E, 'M': c_M, 'O': c_O, 'I': c_I, 'S': c_Sx, 'F': c_F,
        '@': c_index, '>': c_repeat, 'J': c_J, '?': c_ver, 'Q': c_Q,
    }

    # ------------------------------------------------------------------ rig
    def set_input(self, t, port, val):
        self.inputs[port] = val
        if self.deaf_until is None and not self.jumping:
            self.poll_interrupts(t)

    def state(self, now):
        return {
            "profile": "GVE54",
            "addresses": [int(self.address, 16)],
            "time_ns": now,
            "position": list(self.pos),
            "physical": list(self.phys),
            "excursion": [list(e) for e in self.exc],
            "status": ['%02X' % s for s in self.st] + ['%02X' % self.sr6()],
            "outputs": '%02X' % self.outputs,
            "spindle": 0,
            "rate_position": self.rate_position,
            "rate": self.rate,
            "inputs": {str(i): '%02X' % self.inputs[i] for i in range(3)},
            "queue": len(self.queue),
            "index": self.index,
            "modal": {"V": self.V, "A": self.A, "B": self.B, "$": self.short, "T": self.T},
            "microstep": 16 // self.P,
            "current": "full" if self.current == 'U' else "half",
            "kept": self.kept is not None,
            "moving": self.mstate == Unit.RUN,
            "restarting": self.deaf_until is not None or self.jumping,
            "eeprom": None,
        }


# ====================================================================== cosim
def is_num(s):
    return 0 < len(s) <= 20 and all('0' <= c <= '9' for c in s)


def parse_hex(s):
    if not s or len(s) % 2 or any(c not in '0123456789abcdefABCDEF' for c in s):
        raise ValueError('bad hex')
    return bytes.fromhex(s)


class Cosim:
    def __init__(self, address='0'):
        self.now = 0
        self.baud = 115200
        self.b = round(10 * NS_PER_S / self.baud)
        self.unit = Unit(address)
        self.rxq = []        # (t, byte) on their way to the unit

    def advance(self, limit, cr_rule, out):
        """Run the clock to limit; returns True when stopped at a CR to the host."""
        u = self.unit
        while True:
            ev = u.next_event()
            tr = self.rxq[0][0] if self.rxq else None
            if ev is not None and (tr is None or ev[0] <= tr):
                t = ev[0]
                if t > limit:
                    break
                self.now = t
                _, byte = u.run_event(t, ev[1])
                if byte is not None:
                    out.append((t, byte))
                    if byte == 0x0D and cr_rule:
                        return True
            elif tr is not None:
                if tr > limit:
                    break
                self.now = tr
                _, byte = self.rxq.pop(0)
                u.rx_byte(tr, byte)
            else:
                break
        self.now = limit
        return False

    def do_tx(self, data, T, out):
        end = self.now + len(data) * self.b
        if T is not None and T < end:
            raise ValueError('T before the end of the bytes')
        for i, byte in enumerate(data):
            self.rxq.append((self.now + (i + 1) * self.b, byte))
        self.advance(end, False, out)
        if T is not None and not any(b == 0x0D for _, b in out):
            self.advance(T, True, out)

    def next_event(self):
        u = copy.deepcopy(self.unit)
        for _ in range(20_000_000):
            ev = u.next_event()
            if ev is None:
                return None
            rep, _ = u.run_event(ev[0], ev[1])
            if rep:
                return ev[0]
        return None

    def fmt_rx(self, out):
        """rx lines: bytes that follow each other by one byte time share a line."""
        lines = []
        start, data, last = None, [], None
        for t, b in out:
            if data and t == last + self.b:
                data.append(b)
            else:
                if data:
                    lines.append('rx %d %s' % (start, bytes(data).hex().upper()))
                start, data = t, [b]
            last = t
        if data:
            lines.append('rx %d %s' % (start, bytes(data).hex().upper()))
        return lines

    def handle(self, line):
        w = line.split()
        if not w:
            return None
        cmd = w[0]
        u = self.unit
        if cmd in ('quit', 'exit'):
            if len(w) != 1:
                return ['error: quit takes no arguments']
            raise SystemExit(0)
        if cmd == 'help':
            return ['commands: tx HEX [T] | until T | next | baud N | batch D HEX ... | '
                    'in PORT XX | switch AXIS POS|none | rate POS|none | power-on | state | quit']
        if cmd == 'tx':
            if len(w) not in (2, 3):
                return ['error: tx HEX [T]']
            try:
                data = parse_hex(w[1])
            except ValueError:
                return ['error: bad hex']
            T = None
            if len(w) == 3:
                if not is_num(w[2]):
                    return ['error: bad instant']
                T = int(w[2])
                if T < self.now + len(data) * self.b:
                    return ['error: T before the end of the bytes']
            out = []
            self.do_tx(data, T, out)
            return self.fmt_rx(out) + ['now %d' % self.now]
        if cmd == 'batch':
            if len(w) < 3 or len(w) % 2 != 1:
                return ['error: batch D HEX [D HEX ...]']
            pairs = []
            try:
                for i in range(1, len(w), 2):
                    if not is_num(w[i]):
                        raise ValueError
                    pairs.append((int(w[i]), parse_hex(w[i + 1])))
            except ValueError:
                return ['error: bad batch']
            lines = []
            for d, data in pairs:
                out = []
                T = self.now + len(data) * self.b + d
                self.do_tx(data, T, out)
                lines += self.fmt_rx(out) + ['now %d' % self.now]
                if not any(b == 0x0D for _, b in out):
                    break                               # batch-stops
            return lines
        if cmd == 'until':
            if len(w) != 2 or not is_num(w[1]):
                return ['error: until T']
            T = int(w[1])
            if T < self.now:
                return ['error: until before now']
            out = []
            self.advance(T, True, out)
            return self.fmt_rx(out) + ['now %d' % self.now]
        if cmd == 'next':
            if len(w) != 1:
                return ['error: next takes no arguments']
            t = self.next_event()
            return ['next none' if t is None else 'next %d' % t]
        if cmd == 'baud':
            if len(w) != 2 or not is_num(w[1]) or int(w[1]) == 0:
                return ['error: baud N']
            self.baud = int(w[1])
            self.b = round(10 * NS_PER_S / self.baud)
            u.bt = self.b
            u.line_baud = self.baud
            return ['ok']
        # rig commands, optional trailing @ADDRESS
        if len(w) > 1 and w[-1].startswith('@'):
            a = w[-1][1:]
            if not is_num(a) or int(a) != int(u.address, 16):
                return ['error: no unit at address %s' % a]
            w = w[:-1]
        if cmd == 'state':
            if len(w) != 1:
                return ['error: state takes no arguments']
            return [json.dumps(u.state(self.now))]
        if cmd == 'in':
            if len(w) != 3 or w[1] not in ('0', '1', '2') or len(w[2]) != 2:
                return ['error: in PORT XX']
            try:
                val = parse_hex(w[2])[0]
            except ValueError:
                return ['error: bad hex']
            u.set_input(self.now, int(w[1]), val)
            return ['ok']
        if cmd == 'switch':
            if len(w) != 3 or w[1] not in ('X', 'Y', 'Z'):
                return ['error: switch AXIS POS|none (axes X Y Z)']
            p = w[2]
            if p != 'none':
                q = p[1:] if p[:1] in '+-' else p
                if not is_num(q):
                    return ['error: bad position']
            return ['ok']            # the GVE54 has no reference run: nothing sees it [R39]
        if cmd == 'rate':
            if len(w) != 2:
                return ['error: rate POS|none']
            if w[1] == 'none':
                u.rate_position = None
                return ['ok']
            if not is_num(w[1]) or int(w[1]) >= len(RATE_POSITIONS):
                return ['error: rate position 0..%d' % (len(RATE_POSITIONS) - 1)]
            u.rate_position = int(w[1])
            return ['ok']
        if cmd == 'power-on':
            if len(w) != 1:
                return ['error: power-on takes no arguments']
            u.power_on(self.now)
            return ['ok']
        return ["error: unknown command '%s'" % cmd]


def main():
    args = sys.argv[1:]
    address = '0'
    if '--address' in args:
        i = args.index('--address')
        address = args[i + 1].upper()
        if len(address) != 1 or address not in '0123456789ABCDEF':
            sys.stderr.write('--address takes one hex digit\n')
            return 2
    if '--cosim' not in args:
        sys.stderr.write('usage: sim.py --cosim [--address N]\n')
        return 2
    sim = Cosim(address)
    out = sys.stdout
    out.write('cosim 1 batch batch-stops\n')
    out.flush()
    for line in sys.stdin:
        line = line.rstrip('\n').rstrip('\r')
        try:
            rep = sim.handle(line)
        except SystemExit:
            return 0
        if rep is None:
            continue
        out.write('\n'.join(rep) + '\n')
        out.flush()
    return 0


if __name__ == '__main__':
    sys.exit(main())
