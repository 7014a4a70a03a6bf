"""One GVE114 unit: the firmware's behaviour as read from the vendor manual.

The unit is driven by a host loop (sim.py) that calls
  receive(t, byte)   when a byte from the host is complete at the receiver,
  next_event()       for the earliest instant the unit acts by itself,
  fire(t)            to run everything due at t,
and gives it a callback send(t, bytes) that hands answer bytes to the
transmitter at instant t.  Readings of the manual are numbered R<n>
(see READINGS.md).
"""
import math
import re
import struct
from collections import deque

from motion import NS, Vector, profile, stop_profile, evaluate

MODELS = {
    'GVE114-50': 50_000,
    'GVE114-125': 125_000,
    'GVE114-200': 200_000,
    'GVE114-500': 500_000,
}
RESTART_NS = 2_000_000_000          # 13.5 "cca po 2s"
WATCHDOG_NS = 100_000_000           # R5
QUEUE_CAP = 2048                    # 13.6.2, R11
LOOKAHEAD = 32                      # R17
MAX_FRAME = 250                     # R7
MAXP = 2147483647
SERIAL_ID = '16091801'              # R3
# 10.1: (sw1, sw2) in the order of the manual's table = rig positions 0..3
RATE_HIGH = [921000, 460800, 230400, 115200]   # EEPROM 0x0D == 01
RATE_LOW = [19200, 38400, 57600, 115200]       # EEPROM 0x0D == FF (and others, R45)
AXES = 'XYZA'
# 13.6.11: output byte bits; 11.1: EEPROM address of each OUTn's function
OUT_BIT = {1: 2, 2: 3, 3: 1}         # OUT1 -> bit2, OUT2 -> bit3, OUT3 -> bit1

DEC_RE = re.compile(r'[+-]?[0-9]{1,12}$')
UDEC_RE = re.compile(r'[0-9]{1,12}$')
HEX_RE = re.compile(r'[0-9A-Fa-f]{1,8}$')
FLOAT_RE = re.compile(r'[+-]?([0-9]+\.?[0-9]*|\.[0-9]+)([eE][+-]?[0-9]+)?$')
CMD_RE = re.compile(r'(EFR|EUR|EFW|EUW|ER|EW|VL|VK|VN|XA|XU|XD|XM|PF|SR|SW|\*S|\*E|'
                    r'[?QLCT$AVBPNWYKRHDGOIF@>J%])')
ADDR7_CMDS = {'V', '?', 'Q', '>', '@', 'J', '%', 'ER', 'EFR', 'EUR', 'EW', 'EFW', 'EUW'}


class Err(Exception):
    def __init__(self, code):
        self.code = code


def p_int(s, lo, hi):
    if not DEC_RE.match(s):
        raise Err(4)
    v = int(s)
    if not lo <= v <= hi:
        raise Err(5)
    return v


def p_hex(s, hi=0xFF):
    if not HEX_RE.match(s):
        raise Err(4)
    v = int(s, 16)
    if v > hi:
        raise Err(5)
    return v


def nparams(params, *counts):
    if len(params) not in counts:
        raise Err(4)


def fmt_float(x):
    if math.isnan(x):
        return 'nan'
    if math.isinf(x):
        return 'inf' if x > 0 else '-inf'
    for p in range(1, 10):
        s = '%.*g' % (p, x)
        if struct.unpack('<f', struct.pack('<f', float(s)))[0] == x:
            break
    out = repr(float(s))
    return out[:-2] if out.endswith('.0') else out


def csum(text):
    return sum(text.encode('latin-1')) & 0xFF


class Unit:
    def __init__(self, model='GVE114-500', eeprom=None):
        self.model = model
        self.fmax = MODELS[model]
        self.send = lambda t, data: None
        self.eeprom = bytearray(eeprom) if eeprom else bytearray(b'\xff' * 256)  # R39
        self.inputs = [0xFF, 0xFF, 0xFF]
        self.switches = {a: None for a in AXES}
        self.rate_position = None
        self.rate = None
        self.cnt = [0, 0, 0, 0]
        self.phys = [0, 0, 0, 0]
        self.exc = [[0, 0] for _ in range(4)]
        self.queue = deque()
        self.mode = 'idle'
        self.plan = []
        self.t_motion = None
        self.w = None
        self.pending = None          # deferred answer kind: 'H' or 'W'
        self.rx = None
        self.wd = None
        self.last_answer = None
        self._reset(0, power=True)
        self.restart_until = None    # the simulator starts with the unit ready

    # ------------------------------------------------------------ reset
    def _reset(self, t, power):
        if self.mode in ('run', 'stop'):
            self._commit_partial(t)
        elif self.mode == 'w':
            self._w_commit(t)
        self.queue.clear()
        self.mode = 'idle'
        self.plan = []
        self.t_motion = None
        self.w = None
        self.pending = None
        self.cnt = [0, 0, 0, 0]
        self.st = [0] * 6
        self.inta = 0
        self.intcom = 0
        self.raw6 = 0
        self.V = 1000
        self.A = 20
        self.short = 512
        self.B = self.fmax            # R12
        self.T = 5                    # R13
        self.vk = False               # R14
        self.vl = [self.fmax] * 4
        self.xm = 100
        self.out_written = 0xFF
        self.spindle = 0
        self.checksum = False
        self.index = 0
        self.last_answer = None
        self.packet = None
        self.kept = None
        self.rx = None
        self.wd = None
        e = self.eeprom
        # R38: configuration read from EEPROM at every reset
        self.dirsign = [1 if (e[5] >> (4 + i)) & 1 else -1 for i in range(4)]
        self.couple = {1: 0, 2: 1, 3: 2}.get(e[0x0C])
        self.out_func = {n: e[n] for n in (1, 2, 3)}
        if any(v == 0x08 for v in self.out_func.values()):
            self.brake_at = t + min(e[0xFD], 50) * 100_000_000
        else:
            self.brake_at = None
        self.brake_on = False
        self.mpg = '&' if self._mpg_valid() else '-'      # R46
        if power:
            if self.rate_position is None:
                self.rate = None
            else:
                tab = RATE_HIGH if e[0x0D] == 0x01 else RATE_LOW
                self.rate = tab[self.rate_position]
        self.restart_until = t + RESTART_NS

    def _mpg_valid(self):
        e = self.eeprom
        mode = e[6]
        if mode not in (0x01, 0x02, 0x81, 0x82):
            return False
        f = lambda a: struct.unpack('<f', bytes(e[a:a + 4]))[0]
        u = lambda a: struct.unpack('<I', bytes(e[a:a + 4]))[0]
        axes = 4 if mode & 0x80 else 3
        try:
            for i in range(axes):
                if not (0 <= f(0x10 + 4 * i) <= 10000 and 0 <= f(0x20 + 4 * i) <= 10000):
                    return False
                if not 1 <= f(0x30 + 4 * i) <= 10000:
                    return False
            if not 1 <= f(0x40) <= 10000:
                return False
            vmax = f(0x44)
            spm = max(f(0x30 + 4 * i) for i in range(axes))
            if not (vmax > 0 and vmax * spm <= self.fmax / 4):
                return False
            if not 1 <= u(0x48) <= 2000:
                return False
            if not f(0x60) > 0:
                return False
        except (ValueError, OverflowError):
            return False
        return True

    # ------------------------------------------------------------ rig
    def rig_power_on(self, t):
        self._reset(t, power=True)

    def rig_in(self, t, port, val):
        self.inputs[port] = val
        if port == 0:
            return                    # the GVE114 has no port 0
        self._check_intr(t)
        self._w_input(t)

    def port_value(self, port):
        if port == 2:
            return self.inputs[2] | 0x3F   # R26: bits 0-5 have no terminal
        return self.inputs[port]

    # ------------------------------------------------------------ status
    def run_bit(self):
        return 1 if (self.queue or self.mode in ('run', 'stop', 'dwell', 'w')
                     or self.mpg != '-') else 0

    def st6(self):
        return ((self.inta << 7) | (self.run_bit() << 6) | (self.intcom << 4)
                | self.raw6 | (1 if self.mode == 'stop' else 0))

    def cap(self):
        return 1 if self.kept is not None else QUEUE_CAP

    def flag(self):
        full = 1 if len(self.queue) >= self.cap() else 0
        return self.st6() | (full << 5)

    def moving(self):
        return self.mode in ('run', 'stop', 'dwell', 'w')

    def outputs(self, t=None):
        v = self.out_written
        for n, fn in self.out_func.items():
            if (fn == 0x08 and self.brake_on) or (fn == 0x09 and self.inta):
                v &= ~(1 << OUT_BIT[n]) & 0xFF
        return v

    # ------------------------------------------------------------ positions
    def _head_delta(self, t):
        if self.mode in ('run', 'stop') and self.queue:
            r = evaluate(self.plan, t)
            s = r[0] if r else self.plan_s0
            return self.queue[0].delta(s)
        if self.mode == 'w' and self.w:
            return self._w_delta(t)
        return [0, 0, 0, 0]

    def positions(self, t):
        d = self._head_delta(t)
        return [self.cnt[i] + d[i] for i in range(4)]

    def physical(self, t):
        d = self._head_delta(t)
        p = [self.phys[i] + self.dirsign[i] * d[i] for i in range(4)]
        self._exc(p)
        return p

    def _exc(self, p):
        for i in range(4):
            if p[i] < self.exc[i][0]:
                self.exc[i][0] = p[i]
            if p[i] > self.exc[i][1]:
                self.exc[i][1] = p[i]

    def _commit(self, d):
        for i in range(4):
            self.cnt[i] += d[i]
            self.phys[i] += self.dirsign[i] * d[i]
        self._exc(self.phys)

    # ------------------------------------------------------------ motion
    def cruise(self, v):
        sp = v.V * self.xm / 100.0 * v.k
        if v.short:
            sp = min(sp, v.B * v.k)
        for i in range(4):
            if v.d[i]:
                sp = min(sp, self.vl[i] * v.L / abs(v.d[i]))
        return max(1.0, min(sp, float(self.fmax)))

    def junction(self):
        q = self.queue
        n = min(len(q), LOOKAHEAD)
        e = 0.0
        for j in range(n - 2, -1, -1):
            nxt = q[j + 1]
            if nxt.kind != 'C':
                e = 0.0
                continue
            cur = q[j]
            e = min(cur.B * cur.k, self.cruise(cur), self.cruise(nxt),
                    math.sqrt(e * e + 2 * nxt.A * nxt.L))
        return e

    def _plan_head(self, t, s0, v0):
        h = self.queue[0]
        self.mode = 'run'
        self.plan_s0 = s0
        self.plan, self.plan_vend = profile(t, s0, v0, h.L, self.cruise(h),
                                            self.junction(), h.A)
        self.t_motion = self.plan[-1][1] if self.plan else t

    def _replan(self, t):
        if self.mode != 'run' or not self.queue:
            return
        r = evaluate(self.plan, t)
        s, v = r if r else (self.plan_s0, self.plan_vend)
        self._plan_head(t, s, v)

    def _start(self, t):
        """Start the queue from rest if the interpolator may run."""
        if self.queue and self.mode in ('idle', 'held'):
            if self.inta:
                self.mode = 'held'
            else:
                self._plan_head(t, 0.0, 0.0)

    def _begin_stop(self, t):
        if self.mode == 'run':
            r = evaluate(self.plan, t)
            s, v = r if r else (self.plan_s0, 0.0)
            self._stop_plan(t, s, v)
        elif self.mode == 'dwell':
            self.mode = 'idle'
            self.t_motion = None

    def _stop_plan(self, t, s, v):
        h = self.queue[0]
        self.mode = 'stop'
        self.plan_s0 = s
        self.plan, self.plan_vend, self.stop_inside = stop_profile(t, s, v, h.L, h.A)
        self.t_motion = self.plan[-1][1] if self.plan else t

    def _commit_partial(self, t):
        """Commit the pulses done by the head vector and shorten it (R18)."""
        if not self.queue:
            return
        r = evaluate(self.plan, t)
        s = r[0] if r else self.plan_s0
        self._split_head(int(math.floor(s + 1e-9)))

    def _split_head(self, s_int):
        h = self.queue[0]
        d = h.delta(s_int)
        self._commit(d)
        if s_int >= h.L:
            self.queue.popleft()
        else:
            h.d = [h.d[i] - d[i] for i in range(4)]
            h.recompute()
        self.plan = []
        self.t_motion = None

    def _motion_event(self, t):
        if self.mode == 'run':
            h = self.queue.popleft()
            self._commit(h.d)
            vend = self.plan_vend
            self.plan = []
            if self.queue:
                if self.queue[0].kind == 'C':
                    self._plan_head(t, 0.0, vend)
                else:
                    self._plan_head(t, 0.0, 0.0)
            else:
                self.mode = 'dwell'                    # R13
                self.t_motion = t + self.T * 1_000_000
        elif self.mode == 'dwell':
            self.mode = 'idle'
            self.t_motion = None
            self._start(t)
        elif self.mode == 'stop':
            h = self.queue[0]
            if self.stop_inside:
                s = self.plan[-1][3] if self.plan else self.plan_s0
                s_int = min(h.L, int(math.ceil(s - 1e-6)))
                self._split_head(s_int)
                self._stopped(t)
            else:
                vend = self.plan_vend
                self.queue.popleft()
                self._commit(h.d)
                if self.queue and vend > 1e-3:
                    self._stop_plan(t, 0.0, vend)
                else:
                    self._stopped(t)
        elif self.mode == 'w':
            self._w_event(t)

    def _stopped(self, t):
        self.plan = []
        self.t_motion = None
        self.mode = 'held' if self.queue else 'idle'
        if self.pending == 'H':
            self.pending = None
            self._answer(t, 0, '')
        if not self.inta:          # INTA cleared by SW6 meanwhile
            self._start(t)

    def _set_inta(self, t):
        self.inta = 1
        self._begin_stop(t)

    # ------------------------------------------------------------ W
    def _w_delta(self, t):
        w = self.w
        steps = min(w['target'], int((t - w['t0']) * w['rate'] // NS))
        d = [0, 0, 0, 0]
        d[w['axis']] = steps * w['dir']
        if self.couple is not None and self.couple == w['axis']:
            d[3] = d[w['axis']]
        return d

    def _w_commit(self, t):
        self._commit(self._w_delta(t))

    def _w_stage(self, t, stage, direction, rate, target):
        w = self.w
        w.update(stage=stage, dir=direction, rate=rate, target=target, t0=t)
        self.t_motion = t + (target * NS + rate - 1) // rate if target else t

    def _ref_active(self, ax):
        bit = ax                      # IN0..IN3 = ref X, Y, Z, A (8.)
        inp = (self.inputs[1] >> bit) & 1
        pol = (self.st[2] >> bit) & 1
        return inp == pol

    def _start_w(self, t, ax, n2, n3, n4, n5):
        cdir = 1 if n2 > 0 else -1
        self.w = dict(axis=ax, n2=abs(n2), n3=n3, n4=n4, n5=n5)
        self.mode = 'w'
        sw = self.switches[AXES[ax]]
        if sw is not None:
            p = self.phys[ax]
            pdir = cdir * self.dirsign[ax]
            dist = (sw - p) * pdir
            found = 0 <= dist <= abs(n2)
            self.w['by'] = 'switch'
            self.w['found'] = found
            self._w_stage(t, 'to', cdir, n3, dist if found else abs(n2))
        else:
            self.w['by'] = 'input'
            act = self._ref_active(ax)
            self.w['found'] = act
            self._w_stage(t, 'to', cdir, n3, 0 if act else abs(n2))

    def _w_event(self, t):
        w = self.w
        self._w_commit(t)
        if w['stage'] == 'to':
            if not w['found']:
                self._w_done(t, 5)            # R35
                return
            back = 1 if w['by'] == 'switch' else w['n4']
            if w['by'] == 'input' and not self._ref_active(w['axis']):
                self._w_done(t, 0, zero=True)
                return
            self._w_stage(t, 'back', -w['dir'], w['n5'], back)
        else:
            if w['by'] == 'switch':
                self._w_done(t, 0, zero=True)
            else:
                self._w_done(t, 5)

    def _w_input(self, t):
        w = self.w
        if self.mode != 'w' or w is None or w['by'] != 'input':
            return
        act = self._ref_active(w['axis'])
        if w['stage'] == 'to' and act:
            self._w_commit(t)
            w['found'] = True
            self._w_stage(t, 'back', -w['dir'], w['n5'], w['n4'])
        elif w['stage'] == 'back' and not act:
            self._w_commit(t)
            self._w_done(t, 0, zero=True)

    def _w_done(self, t, err, zero=False):
        ax = self.w['axis']
        if zero:
            self.cnt[ax] = 0
        self.w = None
        self.mode = 'idle'
        self.t_motion = None
        if self.pending == 'W':
            self.pending = None
            self._answer(t, err, '')

    # ------------------------------------------------------------ interrupts
    def _check_intr(self, t):
        new_any = False
        for port, en, pol, cause, mask in ((1, 0, 2, 4, 0xFF), (2, 1, 3, 5, 0xC0)):
            inp = self.port_value(port)
            active = ~(inp ^ self.st[pol]) & mask
            new = active & self.st[en] & ~self.st[cause] & 0xFF
            if new:
                self.st[cause] |= new
                new_any = True
        if new_any:
            self._set_inta(t)

    # ------------------------------------------------------------ events
    def next_event(self):
        c = [x for x in (self.t_motion, self.wd, self.restart_until, self.brake_at)
             if x is not None]
        return min(c) if c else None

    def fire(self, t):
        for _ in range(100000):
            if self.restart_until is not None and self.restart_until <= t:
                self.restart_until = None
                continue
            if self.brake_at is not None and self.brake_at <= t:
                self.brake_at = None
                self.brake_on = True
                continue
            if self.wd is not None and self.wd <= t:
                self.wd = None
                self._watchdog(t)
                continue
            if self.t_motion is not None and self.t_motion <= t:
                self.t_motion = None
                self._motion_event(t)
                continue
            break

    def _watchdog(self, t):
        fr = self.rx
        self.rx = None
        if fr is not None and len(fr) >= 2 and fr[1] in (0x30, 0x37):
            if self.packet is not None and fr[1] == 0x30:
                self.packet['err'] = self.packet['err'] or 2
            else:
                self._answer(t, 2, '')

    # ------------------------------------------------------------ receiver
    def receive(self, t, b):
        if self.restart_until is not None and t < self.restart_until:
            return
        if b == 0x21:                 # '!' starts a frame (R6)
            self.rx = bytearray(b'!')
            self.wd = t + WATCHDOG_NS
            return
        if self.rx is None:
            return
        if b == 0x0D:
            fr = bytes(self.rx)
            self.rx = None
            self.wd = None
            self._frame(t, fr)
            return
        if len(self.rx) < MAX_FRAME:
            self.rx.append(b)
        else:
            self.rx.append(0)          # marks an over-long frame (R7)
            del self.rx[MAX_FRAME:]

    # ------------------------------------------------------------ answers
    def _answer(self, t, err, extra, remember=True):
        text = '%X' % ((self.inta << 3) | err) + extra
        if self.checksum:
            text += ','
            text += '%02X' % csum(text)
        data = (text + '\r').encode('latin-1')
        if remember:
            self.last_answer = data
        self.send(t, data)

    def _frame(self, t, fr):
        if len(fr) < 2 or fr[1] not in (0x30, 0x37):
            return                    # another unit's frame (or none)
        addr = fr[1] - 0x30
        text = fr.decode('latin-1')
        body = text[2:]
        try:
            if self.checksum:
                m = re.fullmatch(r'(.*),([0-9A-Fa-f]{2})', text, re.S)
                if not m or csum(text[:len(m.group(1)) + 1]) != int(m.group(2), 16):
                    raise Err(4)                                  # R9
                body = m.group(1)[2:]
            elif re.fullmatch(r'%[+-],[0-9A-Fa-f]{2}', body):
                if csum(text[:5]) != int(body[3:], 16):
                    raise Err(4)
                body = body[:2]
            if '\x00' in body or any(ord(c) > 126 or ord(c) < 32 for c in body):
                raise Err(4)
            m = CMD_RE.match(body)
            if not m:
                raise Err(3)
            cmd = m.group(1)
            rest = body[len(cmd):]
            if addr == 7 and cmd not in ADDR7_CMDS:
                raise Err(3)
        except Err as e:
            if self.packet is not None:
                self.packet['err'] = self.packet['err'] or e.code
                return
            self._answer(t, e.code, '')
            return
        # packets (13.4, R50)
        if self.packet is not None:
            if addr == 0 and cmd in ('C', 'B'):
                if self.packet['err']:
                    return
                try:
                    self._exec(t, addr, cmd, rest)
                    self.packet['count'] += 1
                    self.index = (self.index + 1) & 0xFF
                except Err as e:
                    self.packet['err'] = e.code
                return
            if addr == 0 and cmd == '*E':
                pk = self.packet
                self.packet = None
                err = pk['err']
                try:
                    n = p_int(rest, 0, MAXP)
                except Err as e:
                    err = err or e.code
                    n = pk['count']
                if not err and n != pk['count']:
                    err = 2
                if not err:
                    self.index = (self.index + 1) & 0xFF
                self._answer(t, err, ',%d' % pk['count'])
                return
            self.packet = None        # any other command abandons the packet
        if cmd == '>':
            if rest:
                self._answer(t, 4, '')
            elif self.last_answer is None:
                self._answer(t, 0, '')
            else:
                self.send(t, self.last_answer)
            return
        if cmd == '*S' and addr == 0:
            if rest:
                self._answer(t, 4, '')
                return
            self.packet = {'count': 0, 'err': 0}
            self.index = (self.index + 1) & 0xFF
            return
        try:
            r = self._exec(t, addr, cmd, rest)
        except Err as e:
            self._answer(t, e.code, '')
            return
        if cmd != '@':
            self.index = (self.index + 1) & 0xFF
        if r is None:
            return                     # deferred (H, W)
        if cmd == 'J':
            self._answer(t, 0, '')
            self._reset(t, power=False)   # R47
            return
        self._answer(t, 0, r)

    # ------------------------------------------------------------ commands
    def _exec(self, t, addr, cmd, rest):
        P = rest.split(',') if rest != '' else []
        none = lambda: nparams(P, 0)
        if cmd == '?':
            none()
            return ',IP114/%d x16 16.9.2018' % (self.fmax // 1000)   # R2
        if cmd == 'Q':
            none()
            return ',' + SERIAL_ID
        if cmd == 'V' and addr == 7:
            nparams(P, 1)
            v = p_int(P[0], 0, 1000)
            self.spindle = v
            if v:
                self.out_written &= 0xFE
            else:
                self.out_written |= 0x01
            return ''
        if cmd in ('L', 'C'):
            nparams(P, 3, 4)                                    # R10
            d = [p_int(x, -MAXP, MAXP) for x in P] + [0] * (4 - len(P))
            return self._vector(t, cmd, d)
        if cmd == 'T':
            nparams(P, 1)
            self.T = p_int(P[0], 1, 24)
            return ''
        if cmd == '$':
            nparams(P, 1)
            self.short = p_int(P[0], 1, MAXP)
            return ''
        if cmd == 'A':
            nparams(P, 1)
            self.A = p_int(P[0], 1, 100000)                       # R15
            return ''
        if cmd == 'V':
            nparams(P, 1)
            self.V = p_int(P[0], 10, self.fmax)                   # R12
            return ''
        if cmd == 'VL':
            nparams(P, 3, 4)
            v = [p_int(x, 10, self.fmax) for x in P]              # R16
            self.vl[:len(v)] = v
            self._replan(t)
            return ''
        if cmd == 'B':
            nparams(P, 1)
            self.B = p_int(P[0], 10, self.fmax)
            return ''
        if cmd in ('VK', 'VN'):
            none()
            self.vk = cmd == 'VK'
            return ''
        if cmd in ('XA', 'XU', 'XD'):
            none()
            for v in self.queue:
                if cmd == 'XA':
                    v.V = self.V
                elif cmd == 'XU':
                    v.V = min(self.fmax, v.V + v.V / 16.0)
                else:
                    v.V = max(10.0, v.V - v.V / 16.0)
            self._replan(t)
            return ''
        if cmd == 'XM':
            nparams(P, 1)
            self.xm = p_int(P[0], 1, 1000)                        # R19
            for v in self.queue:
                v.V = self.V
            self._replan(t)
            return ''
        if cmd == 'P':
            none()
            p = self.positions(t)
            return ',%d,%d' % (p[0], p[1])
        if cmd == 'PF':
            none()
            p = self.positions(t)
            return ',%d,%d,%d' % (p[0], p[1], p[2])
        if cmd == 'N':
            if rest == '':
                if self.run_bit():
                    raise Err(7)
                self.cnt = [0, 0, 0, 0]                           # R33
                return ''
            ax = AXES.find(rest[0].upper())
            if ax < 0:
                raise Err(4)
            PP = rest[1:].split(',')
            nparams(PP, 1)
            v = p_int(PP[0], -MAXP, MAXP)
            if self.run_bit():
                raise Err(7)
            self.cnt[ax] = v
            return ''
        if cmd == 'W':
            if not rest or rest[0].upper() not in AXES:
                raise Err(4)
            ax = AXES.index(rest[0].upper())
            PP = rest[1:].split(',')
            nparams(PP, 4)
            n2 = p_int(PP[0], -MAXP, MAXP)
            n3 = p_int(PP[1], 10, self.fmax)
            n4 = p_int(PP[2], 1, MAXP)
            n5 = p_int(PP[3], 10, self.fmax)
            if n2 == 0:
                raise Err(5)
            if self.run_bit() or self.moving():
                raise Err(7)
            self.pending = 'W'
            self._start_w(t, ax, n2, n3, n4, n5)
            self.fire(t)
            return None
        if cmd == 'Y':
            if rest not in ('+', '&', '-'):
                raise Err(5 if len(rest) == 1 else 4)
            if rest != '-':
                if self.queue or self.moving():
                    raise Err(7)
                if not self._mpg_valid():
                    raise Err(5)                                  # R46
            self.mpg = rest
            return ',Y' + rest
        if cmd == 'K':
            none()
            if self.moving() or self.kept is not None:
                raise Err(7)
            self.kept = (list(self.queue), self.st[4], self.st[5],
                         self.inta, self.intcom, self.raw6)
            self.queue.clear()
            self.st[4] = self.st[5] = 0
            self.inta = self.intcom = self.raw6 = 0
            self.mode = 'idle'
            self._check_intr(t)
            return ''
        if cmd == 'R':
            none()
            if self.moving() or self.kept is None or self.queue:
                raise Err(7)
            q, self.st[4], self.st[5], self.inta, self.intcom, self.raw6 = self.kept
            self.kept = None
            self.queue.extend(q)
            self.mode = 'idle'
            self._start(t)
            return ''
        if cmd == 'H':
            none()
            self.inta = 1
            self.intcom = 1
            if self.mode == 'w':
                self._w_commit(t)
                self.w = None
                self.mode = 'idle'
                self.t_motion = None
                self.pending = None                               # R36
            if self.mode in ('run', 'stop'):
                if self.mode == 'run':
                    self._begin_stop(t)
                self.pending = 'H'
                self.fire(t)
                return None
            self._begin_stop(t)
            return ''
        if cmd == 'D':
            none()
            if self.moving():
                raise Err(7)
            self.queue.clear()
            self.mode = 'idle'
            self.st[4] = self.st[5] = 0
            self.inta = self.intcom = self.raw6 = 0
            self._check_intr(t)
            return ''
        if cmd == 'G':
            none()
            if self.mode == 'stop':
                raise Err(7)
            if not self.inta:
                raise Err(6)
            self.inta = self.intcom = 0
            self.st[4] = self.st[5] = 0
            if not self.queue:
                self._check_intr(t)
                raise Err(6)
            self._start(t)
            self._check_intr(t)
            return ''
        if cmd in ('ER', 'EFR', 'EUR'):
            nparams(P, 1)
            a = p_hex(P[0], 0xFF if cmd == 'ER' else 0xFC)
            if cmd == 'ER':
                return ',%02X' % self.eeprom[a]
            raw = bytes(self.eeprom[a:a + 4])
            if cmd == 'EFR':
                return ',' + fmt_float(struct.unpack('<f', raw)[0])
            return ',%d' % struct.unpack('<I', raw)[0]
        if cmd in ('EW', 'EFW', 'EUW'):
            nparams(P, 2)
            a = p_hex(P[0], 0xFF if cmd == 'EW' else 0xFC)
            if cmd == 'EW':
                self.eeprom[a] = p_hex(P[1])
            elif cmd == 'EFW':
                if not FLOAT_RE.match(P[1]):
                    raise Err(4)
                try:
                    raw = struct.pack('<f', float(P[1]))
                except OverflowError:
                    raise Err(5)
                if math.isinf(struct.unpack('<f', raw)[0]):
                    raise Err(5)
                self.eeprom[a:a + 4] = raw
            else:
                if not UDEC_RE.match(P[1]):
                    raise Err(4)
                v = int(P[1])
                if v > 0xFFFFFFFF:
                    raise Err(5)
                self.eeprom[a:a + 4] = struct.pack('<I', v)
            return ''
        if cmd == 'O':
            nparams(P, 2)
            port = p_int(P[0], 0, 255)
            val = p_hex(P[1])
            if port != 0:
                raise Err(5)
            self.out_written = val
            return ''
        if cmd == 'I':
            nparams(P, 1)
            port = p_int(P[0], 0, 255)
            if port not in (1, 2):
                raise Err(5)                                      # R26
            return ',%02X' % self.port_value(port)
        if cmd == 'SR':
            nparams(P, 1)
            n = p_int(P[0], 0, 255)
            if n > 6:
                raise Err(5)
            return ',%02X' % (self.st6() if n == 6 else self.st[n])
        if cmd == 'SW':
            nparams(P, 2)
            n = p_int(P[0], 0, 255)
            x = p_hex(P[1])
            if n > 6:
                raise Err(5)
            if n == 6:
                self._sw6(t, x)
            else:
                self.st[n] = x
                self._check_intr(t)
            return ''
        if cmd == 'F':
            none()
            return ',%02X' % self.flag()
        if cmd == '@':
            none()
            return ',%d' % self.index                             # R4
        if cmd == 'J':
            none()
            return ''
        if cmd == '%':
            if rest == '+':
                self.checksum = True
            elif rest == '-':
                self.checksum = False
            else:
                raise Err(4)
            return ''
        if cmd == '*E':
            raise Err(4)                                          # no packet open
        if cmd == '*S':
            raise Err(4)
        raise Err(3)

    def _sw6(self, t, x):
        old = self.inta
        self.raw6 = x & 0x2E
        self.intcom = (x >> 4) & 1
        self.inta = (x >> 7) & 1
        if self.inta and not old:
            self._begin_stop(t)
        elif old and not self.inta and self.mode == 'held':
            self._start(t)

    def _vector(self, t, kind, d):
        if self.mpg != '-' or self.mode == 'w':
            raise Err(7)
        if self.couple is not None:
            d[3] = d[self.couple]                                 # R40
        if kind == 'L':
            if self.queue or self.moving():                        # 13.6.2 L0,0,0
                raise Err(1)
        else:
            if self.kept is not None or len(self.queue) >= QUEUE_CAP:
                raise Err(1)
        v = Vector(kind, d, self.V, self.A * 1000.0, self.B, self.vk, self.short)
        self.queue.append(v)
        if self.mode in ('idle', 'held'):
            self._start(t)
        elif self.mode == 'run' and len(self.queue) <= LOOKAHEAD:
            self._replan(t)
        return ''

    # ------------------------------------------------------------ state
    def state(self, t):
        pos = self.positions(t)
        phys = self.physical(t)
        return {
            'profile': self.model,
            'addresses': [0, 7],
            'time_ns': t,
            'position': pos,
            'physical': phys,
            'excursion': [list(x) for x in self.exc],
            'status': ['%02X' % v for v in self.st] + ['%02X' % self.st6()],
            'outputs': '%02X' % self.outputs(t),
            'spindle': self.spindle,
            'rate_position': self.rate_position,
            'rate': self.rate,
            'inputs': {str(i): '%02X' % self.inputs[i] for i in range(3)},
            'queue': len(self.queue),
            'index': self.index,
            'checksums': self.checksum,
            'modal': {'V': self.V, 'A': self.A, 'B': self.B, '$': self.short,
                      'T': self.T, 'VK': self.vk, 'VL': list(self.vl), 'XM': self.xm},
            'microstep': 1,
            'mpg': self.mpg,
            'kept': self.kept is not None,
            'packet_open': self.packet is not None,
            'eeprom': None,
            'mutant': None,
            'mode': self.mode,
        }
