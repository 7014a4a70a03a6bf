#!/usr/bin/env python3
"""Gravos GVE114 hardware interpolator - firmware behaviour simulator.

Written from the vendor manual (GVE114-manual.txt) alone; cosim.md / rig.md
give the stdin/stdout protocol.  Places where the manual is silent or
ambiguous are decided as documented in READINGS.md and cited here as [Rn].
Standard library only.
"""
import sys, math, json, struct, copy

MODELS = {"GVE114-500": 500000, "GVE114-200": 200000,
          "GVE114-125": 125000, "GVE114-50": 50000}
QUEUE_MAX = 2048           # "Vnitrni buffer pro 2048 vektoru"
WATCHDOG_NS = 100_000_000  # [R5]
RESTART_NS = 2_000_000_000  # "cca po 2s"
MAXV = 2147483647
SPINDLE_ADDR = 7
# rate switch positions sw1/sw2: 0=OFF/OFF 1=OFF/ON 2=ON/OFF 3=ON/ON  (manual 10.1)
RATES_01 = [921600, 460800, 230400, 115200]   # [R27]
RATES_FF = [19200, 38400, 57600, 115200]

# ST6 bits (manual 13.6.12)
B_STOP, B_FREE, B_INTCOM, B_QFULL, B_RUN, B_INTA = 0x01, 0x02, 0x10, 0x20, 0x40, 0x80  # [R35]


class CmdError(Exception):
    def __init__(self, code):
        self.code = code


def parse_int(s, lo=-MAXV, hi=MAXV):
    s = s.strip()
    if not s:
        raise CmdError(4)
    t = s[1:] if s[0] in "+-" else s
    if not t.isdigit() or not t.isascii():
        raise CmdError(4)
    v = int(s)
    if v < lo or v > hi:
        raise CmdError(5)
    return v


def parse_hex(s, lo=0, hi=0xFF):
    s = s.strip()
    if not s or len(s) > 8 or any(c not in "0123456789abcdefABCDEF" for c in s):
        raise CmdError(4)
    v = int(s, 16)
    if v < lo or v > hi:
        raise CmdError(5)
    return v


class Vector:
    def __init__(self, d, kind, vel):
        self.d = list(d)          # x,y,z,a steps
        self.kind = kind          # 'L' or 'C'
        self.vel = vel            # programmed V (pulses/s) for this vector
        self.done = [0, 0, 0, 0]  # steps already committed (after a halt split)


class Profile:
    """Trapezoid in path units s (0..L) from time t0."""
    def __init__(self, t0, s0, L, v0, vm, ve, a):
        self.t0, self.s0, self.L, self.a = t0, s0, L, a
        D = max(0.0, L - s0)
        v0 = max(0.0, v0)
        vm = max(1.0, vm)
        ve = max(0.0, min(ve, vm, math.sqrt(v0 * v0 + 2 * a * D)))
        if v0 > vm:
            if (v0 * v0 - ve * ve) / (2 * a) <= D:
                vp = vm
            else:
                vp = v0
                ve = math.sqrt(max(0.0, v0 * v0 - 2 * a * D))
        else:
            vp = min(vm, math.sqrt((2 * a * D + v0 * v0 + ve * ve) / 2))
            vp = max(vp, v0, ve)
        d1 = abs(vp * vp - v0 * v0) / (2 * a)
        d3 = (vp * vp - ve * ve) / (2 * a)
        d2 = max(0.0, D - d1 - d3)
        self.v0, self.vp, self.ve = v0, vp, ve
        self.acc1 = a if vp >= v0 else -a
        self.t1 = abs(vp - v0) / a
        self.d1 = d1
        self.t2 = d2 / vp if vp > 0 else 0.0
        self.d2 = d2
        self.t3 = (vp - ve) / a
        self.d3 = d3
        self.T = self.t1 + self.t2 + self.t3 if D > 0 else 0.0

    def at(self, t):
        """(s, v) at absolute time t (ns)."""
        x = (t - self.t0) / 1e9
        if x <= 0:
            return self.s0, self.v0
        if x >= self.T:
            return self.L, self.ve
        if x < self.t1:
            return self.s0 + self.v0 * x + self.acc1 * x * x / 2, self.v0 + self.acc1 * x
        x -= self.t1
        if x < self.t2:
            return self.s0 + self.d1 + self.vp * x, self.vp
        x -= self.t2
        return (min(self.L, self.s0 + self.d1 + self.d2 + self.vp * x - self.a * x * x / 2),
                self.vp - self.a * x)

    def end_ns(self):
        return self.t0 + int(math.ceil(self.T * 1e9))


class Unit:
    def __init__(self, model, address):
        self.model = model
        self.rate = MODELS[model]
        self.address = address
        self.eeprom = bytearray([0xFF] * 256)   # [R20] as shipped: all FF
        self.physical = [0, 0, 0, 0]
        self.excursion = [[0, 0] for _ in range(4)]
        self.inputs = {0: 0xFF, 1: 0xFF, 2: 0xFF}
        self.switches = [None] * 4
        self.rate_position = None
        self.rate_read = None
        self.reset_state(0)

    # ---- reset (manual 13.5) -------------------------------------------
    def reset_state(self, now):
        self.st = [0] * 7                 # ST0..ST6 = 00
        self.A = 20                       # A20 (thousands pulses/s^2)
        self.V = 1000                     # V1000
        self.short = 512                  # $512
        self.B = 50000                    # B50000  [R8]
        self.T = 0                        # [R9]
        self.VK = False                   # [R10] VN after reset
        self.VL = [None, None, None, None]
        self.XM = 100
        self.counter = [0, 0, 0, 0]       # N
        self.outputs = 0xFF               # O0,FF
        self.spindle = 0
        self.checksums = False            # "Po zapnuti napajeni/resetu jsou kontrolni soucty vypnute"
        self.index = 0
        self.queue = []
        self.prof = None
        self.halting = False              # a stop ramp is in progress
        self.halt_answer = False          # H answer owed at the stop
        self.kept = None
        self.last_frame = None
        self.last_answer = None
        self.packet = None
        self.mpg = '-'                    # [R22]
        self.wref = None
        self.last_L_end = -10 ** 18
        self.int_active = [0, 0]          # edge detection of interrupts [R16]
        self.int_active = [self._active(0), self._active(1)]

    # ---- positions ------------------------------------------------------
    def partial(self, now):
        """steps of the current vector done by `now` (per axis), beyond v.done."""
        if not self.queue or self.prof is None:
            return [0, 0, 0, 0]
        v = self.queue[0]
        s, _ = self.prof.at(now)
        L = self.prof.Lfull
        if L <= 0:
            return [0, 0, 0, 0]
        if s >= self.prof.L and self.prof.L >= L - 1e-9:
            f = 1.0
        else:
            f = min(1.0, math.floor(min(s, self.prof.L) + 1e-9) / L)
        rem = [v.d[i] - v.done[i] for i in range(4)]
        return [int(r * f) for r in rem]   # truncation toward zero [R12]

    def wref_partial(self, now):
        if not self.wref:
            return [0, 0, 0, 0]
        w = self.wref
        p = [0, 0, 0, 0]
        if now >= w['t1']:
            moved = w['d1'] + min(w['d2'], int((now - w['t1']) * w['v2'] / 1e9)) * -w['dir']
        else:
            moved = min(abs(w['d1']), int((now - w['t0']) * w['v1'] / 1e9)) * w['dir']
        p[w['axis']] = moved
        return p

    def pos(self, now):
        p = self.partial(now)
        w = self.wref_partial(now)
        return [self.counter[i] + p[i] + w[i] for i in range(4)]

    def phys(self, now):
        p = self.partial(now)
        w = self.wref_partial(now)
        ph = [self.physical[i] + p[i] + w[i] for i in range(4)]
        for i in range(4):
            self.excursion[i][0] = min(self.excursion[i][0], ph[i])
            self.excursion[i][1] = max(self.excursion[i][1], ph[i])
        return ph

    def move_commit(self, delta):
        for i in range(4):
            self.counter[i] += delta[i]
            self.physical[i] += delta[i]
            self.excursion[i][0] = min(self.excursion[i][0], self.physical[i])
            self.excursion[i][1] = max(self.excursion[i][1], self.physical[i])

    # ---- motion planning ------------------------------------------------
    def vec_len(self, v):
        rem = [v.d[i] - v.done[i] for i in range(4)]
        if self.VK:                     # VK: d = sqrt(dx*dx+dy*dy+dz*dz) [R10]
            return math.sqrt(rem[0] ** 2 + rem[1] ** 2 + rem[2] ** 2) or max(abs(x) for x in rem)
        return max(abs(x) for x in rem)

    def vec_vmax(self, v):
        vm = v.vel * self.XM / 100.0
        full = max(abs(x) for x in v.d)
        if full < self.short:           # short vector: only up to B [R11]
            vm = min(vm, self.B)
        L = self.vec_len(v)
        rem = [v.d[i] - v.done[i] for i in range(4)]
        if L > 0:
            for i in range(4):
                if rem[i]:
                    axis_v = vm * abs(rem[i]) / L
                    cap = min(self.rate, self.VL[i]) if self.VL[i] else self.rate
                    if axis_v > cap:
                        vm = vm * cap / axis_v
        return max(vm, 1.0)

    def plan(self, now, v0):
        v = self.queue[0]
        L = self.vec_len(v)
        vm = self.vec_vmax(v)
        if self.halting:
            ve = 0.0
            vm = min(vm, v0)
        elif v.kind == 'C' and len(self.queue) > 1 and self.queue[1].kind == 'C':
            ve = min(self.B, vm, self.vec_vmax(self.queue[1]))
        else:
            ve = 0.0
        a = max(1, self.A) * 1000.0
        if self.halting:
            # decelerate to zero: stop point = s + v^2/2a
            stop = v0 * v0 / (2 * a)
            if stop < L:
                L = stop
                self.halt_split = True
            else:
                self.halt_split = False
        self.prof = Profile(now, 0.0, L, v0, vm, ve, a)
        self.prof.Lfull = self.vec_len(v)

    def replan(self, now):
        """re-plan the executing vector from where it is now."""
        if not self.queue or self.prof is None:
            return
        s, vnow = self.prof.at(now)
        p = self.partial(now)
        v = self.queue[0]
        for i in range(4):
            v.done[i] += p[i]
        self.move_commit(p)
        self.plan(now, vnow)

    def start_next(self, now, v0=0.0):
        if not self.queue:
            self.prof = None
            self.st[6] &= ~B_RUN
            return
        self.st[6] |= B_RUN
        start = now
        if self.queue[0].kind == 'L' and self.T:
            start = max(now, self.last_L_end + self.T * 1_000_000)  # [R9]
        self.plan(start, v0)

    def motion_event_time(self):
        if self.queue and self.prof is not None and not (self.st[6] & B_INTA and not self.halting):
            return self.prof.end_ns()
        return None

    def motion_event(self, now):
        v = self.queue[0]
        if self.halting:
            # the ramp ends here: commit what was done and keep the rest
            p = self.partial(now)
            for i in range(4):
                v.done[i] += p[i]
            self.move_commit(p)
            if all(v.done[i] == v.d[i] for i in range(4)):
                self.queue.pop(0)
            self.prof = None
            self.halting = False
            self.st[6] &= ~B_STOP
            if self.queue:
                self.st[6] |= B_RUN      # INTA=1 RUN=1: rest in queue
            else:
                self.st[6] &= ~B_RUN     # INTA=1 RUN=0: vectors ran out while braking
            if self.halt_answer:
                self.halt_answer = False
                return 'H'
            return None
        ve = self.prof.ve
        p = [v.d[i] - v.done[i] for i in range(4)]
        self.move_commit(p)
        self.queue.pop(0)
        if v.kind == 'L':
            self.last_L_end = now
        self.prof = None
        self.start_next(now, ve if self.queue and v.kind == 'C' else 0.0)
        return None

    def moving(self):
        """'za chodu': vectors being executed and not stopped by INTA [R13]"""
        return bool(self.queue and self.prof is not None) or self.halting or self.wref is not None

    def stop_ramp(self, now):
        """stop the running vector by the ramp (H or an interrupt)."""
        self.st[6] |= B_INTA
        if self.queue and self.prof is not None and not self.halting:
            self.replan_base(now)
            self.halting = True
            self.st[6] |= B_STOP
            _, vnow = self.prof.at(now) if self.prof else (0, 0)
            self.plan(now, self._vnow)
            return True
        return self.halting

    def replan_base(self, now):
        s, vnow = self.prof.at(now)
        self._vnow = vnow
        p = self.partial(now)
        v = self.queue[0]
        for i in range(4):
            v.done[i] += p[i]
        self.move_commit(p)

    # ---- interrupts (manual 13.6.12) ------------------------------------
    def _active(self, k):                             # [R41]
        inp = self.inputs[1] if k == 0 else (self.inputs[2] & 0xC0)
        en, pol = self.st[0 + k], self.st[2 + k]
        if k == 1:
            en &= 0xC0
        # polarity bit 0 = active in log.0
        return (~(inp ^ pol)) & en & 0xFF

    def check_interrupts(self, now):
        for k in (0, 1):
            act = self._active(k)
            new = act & ~self.int_active[k]
            self.int_active[k] = act
            if new:                       # [R16] edge into the active state
                self.st[4 + k] |= new
                self.stop_ramp(now)


class Sim:
    def __init__(self, model, address, baud):
        self.unit = Unit(model, address)
        self.now = 0
        self.baud = baud
        self.b = round(1e10 / baud)
        self.to_unit = []     # (t, byte)
        self.to_host = []     # (t, byte)
        self.tx_free = 0      # instant the transmitter is free
        self.rxbuf = None     # current frame bytes (None: waiting for '!')
        self.wd_deadline = None
        self.deaf_until = None
        self.pending = []     # (t, kind) delayed answers (W)
        self.snap = None

    # ---- transmitter ---------------------------------------------------
    def send(self, text):
        u = self.unit
        if u.checksums:
            body = text + ","
            text = body + "%02X" % (sum(body.encode()) & 0xFF)
        data = (text + "\r").encode()
        t = max(self.now, self.tx_free)               # [R40] no processing delay
        for c in data:
            t += self.b
            self.to_host.append((t, c))
        self.tx_free = t

    def answer(self, code, params=(), remember=True):
        u = self.unit
        head = "%X" % ((code & 7) | (8 if u.st[6] & B_INTA else 0))   # [R36]
        text = ",".join([head] + [str(p) for p in params])
        if remember:
            u.last_answer = text
        if u.packet is not None and remember:
            return
        self.send(text)

    # ---- receiver / framing (manual 13.6) ------------------------------
    def rx_byte(self, c):
        u = self.unit
        if self.deaf_until is not None:
            return                                    # deaf during restart
        if u.rate_read is not None and u.rate_read != self.baud:
            return                                    # [R27] wrong rate: garbage
        if c == 0x21:                                 # '!' starts a frame [R4]
            self.rxbuf = bytearray(b"!")
            self.wd_deadline = self.now + WATCHDOG_NS
            return
        if self.rxbuf is None:
            return
        if c == 0x0D:
            frame = bytes(self.rxbuf)
            self.rxbuf = None
            self.wd_deadline = None
            self.frame(frame)
            return
        self.rxbuf.append(c)
        if len(self.rxbuf) > 255:                     # [R4]
            self.rxbuf = None
            self.wd_deadline = None

    def watchdog(self):
        frame = bytes(self.rxbuf)
        self.rxbuf = None
        self.wd_deadline = None
        if len(frame) >= 2 and self.addr_ok(frame[1:2]):
            self.answer(2)                            # error 2: watchdog

    def addr_ok(self, a):
        try:
            n = int(a.decode())
        except Exception:
            return False
        return n == self.unit.address or n == SPINDLE_ADDR

    def frame(self, frame):
        u = self.unit
        try:
            text = frame.decode("ascii")
        except UnicodeDecodeError:
            return
        if len(text) < 2 or not text[1].isdigit():
            return
        addr = int(text[1])
        if addr != u.address and addr != SPINDLE_ADDR:
            return                                     # not ours: silence [R33]
        body = text[2:]
        if u.checksums:
            # "!0A100,4F": the sum of every char up to and incl. the comma [R6]
            k = text.rfind(",")
            ok = False
            if k >= 0 and len(text) - k - 1 == 2:
                try:
                    ok = int(text[k + 1:], 16) == (sum(text[:k + 1].encode()) & 0xFF)
                except ValueError:
                    ok = False
            if not ok:
                if u.packet is not None:
                    u.packet['errors'].append(4)
                    u.packet['count'] += 1
                else:
                    self.answer(4, remember=False)     # [R6]
                return
            body = text[2:k]
        try:
            self.command(addr, body)
        except Exception as e:                         # never let the model die
            sys.stderr.write("internal error on %r: %r\n" % (text, e))
            self.answer(4, remember=False)

    # ---- commands ------------------------------------------------------
    def command(self, addr, body):
        u = self.unit
        if body == ">":                               # REPEAT [R15]
            if u.last_answer is not None:
                self.send(u.last_answer)
            else:
                self.answer(0, remember=False)
            return
        if body == "@":                               # INDEX [R14]
            self.answer(0, [u.index], remember=False)
            return
        if body.startswith("*S") and addr == u.address and body == "*S":  # packet start [R7]
            u.packet = {'count': 0, 'errors': []}
            return
        if body.startswith("*E") and addr == u.address:
            if u.packet is None:
                self.answer(4)
                return
            p = u.packet
            u.packet = None
            try:
                n = parse_int(body[2:], 0, 255 * 255)
            except CmdError as e:
                self.answer(e.code)
                return
            err = next((e for e in p['errors'] if e), 0)
            if err == 0 and n != p['count']:
                err = 2                                # [R7] commands lost
            self.answer(err, [p['count']])
            return
        try:
            if addr == SPINDLE_ADDR and addr != u.address:
                params = self.cmd_spindle(body)
            else:
                params = self.cmd(body)
        except CmdError as e:
            if u.packet is not None:
                u.packet['count'] += 1
                u.packet['errors'].append(e.code)
            self.answer(e.code)
            return
        if params == 'deferred':
            if u.packet is not None:
                u.packet['count'] += 1
            u.index = (u.index + 1) & 0xFF
            return
        u.index = (u.index + 1) & 0xFF                # [R14]
        if u.packet is not None:
            u.packet['count'] += 1
            u.packet['errors'].append(0)
        if params == 'J':                             # [R30]
            self.answer(0)
            self.restart()
            return
        self.answer(0, params or [])

    def cmd_spindle(self, body):
        u = self.unit
        if body.startswith("V"):
            n = parse_int(body[1:], 0, 1000)
            u.spindle = n
            if n == 0:
                u.outputs |= 0x01                     # !7V0 switches OUT0 off
            else:
                u.outputs &= ~0x01                    # !7V1..1000 switches OUT0 on
            return []
        if body and body[0] in "?QJ%E":
            return self.cmd(body)
        raise CmdError(3)

    def cmd(self, body):
        u = self.unit
        now = self.now
        if not body:
            raise CmdError(3)
        c = body[0]
        rest = body[1:]
        if body == "?":
            return ["IP114/%d x16 16.9.2018" % (u.rate // 1000)]   # [R1]
        if body == "Q":
            return ["25022504"]                                    # [R2]
        if c == "%":
            if rest == "+":
                u.checksums = True
            elif rest == "-":
                u.checksums = False
            else:
                raise CmdError(4)
            return []
        if c in "LC" and (len(body) < 2 or body[1] in "+-0123456789"):
            parts = rest.split(",")
            if len(parts) not in (3, 4):                   # [R17]
                raise CmdError(4)
            d = [parse_int(x) for x in parts] + ([0] if len(parts) == 3 else [])
            if u.mpg in "+&":
                raise CmdError(7)
            if u.kept is not None and c == "C":
                raise CmdError(1)                          # after KEEP only L [R18]
            if c == "L":
                # L accepted only when nothing runs or waits [R3]
                if u.queue or u.wref or u.halting:
                    raise CmdError(1)
            else:
                if len(u.queue) >= QUEUE_MAX:
                    raise CmdError(1)
                if u.queue and u.queue[0].kind == 'L' and not (u.st[6] & B_INTA):
                    raise CmdError(1)
            vec = Vector(d, c, u.V)
            u.queue.append(vec)
            if len(u.queue) == 1 and not (u.st[6] & B_INTA):
                u.start_next(now)
            elif len(u.queue) == 2 and u.prof is not None and not u.halting:
                u.replan(now)                              # may now end at B
            return []
        if c == "T":
            u.T = parse_int(rest, 1, 24)
            return []
        if c == "$":
            u.short = parse_int(rest, 1, MAXV)
            return []
        if c == "A":
            u.A = parse_int(rest, 1, 100000)               # [R19]
            return []
        if body.startswith("VL"):
            parts = body[2:].split(",")
            if len(parts) not in (3, 4):
                raise CmdError(4)
            vals = [parse_int(x, 10, 100000) for x in parts]   # [R32]
            for i, x in enumerate(vals):
                u.VL[i] = x                                # pulses/s [R19]
            return []
        if body == "VK":
            u.VK = True
            return []
        if body == "VN":
            u.VK = False
            return []
        if c == "V":
            u.V = parse_int(rest, 10, u.rate)              # [R19]
            return []
        if c == "B":
            u.B = parse_int(rest, 10, u.rate)
            return []
        if body in ("XA", "XU", "XD"):                     # [R37]
            for v in u.queue:
                if body == "XA":
                    v.vel = u.V
                elif body == "XU":
                    v.vel = min(u.rate, v.vel + v.vel / 16.0)
                else:
                    v.vel = max(10, v.vel - v.vel / 16.0)
            if u.prof is not None and not u.halting:
                u.replan(now)
            return []
        if body.startswith("XM"):
            u.XM = parse_int(body[2:], 1, 1000)            # [R19]
            if u.prof is not None and not u.halting:
                u.replan(now)
            return []
        if body == "PF":                                  # [R31]
            p = u.pos(now)
            return p[:3]
        if body == "P":
            p = u.pos(now)
            return p[:2]
        if body == "N":
            if u.st[6] & B_RUN or u.moving():
                raise CmdError(7)                          # "Nelze pouzit za chodu (pri RUN=1)"
            u.counter = [0, 0, 0, 0]
            return []
        if c == "N":
            if not rest or rest[0] not in "XYZA":
                raise CmdError(4)
            n = parse_int(rest[1:])
            if u.moving():
                raise CmdError(7)                          # [R13]
            u.counter["XYZA".index(rest[0])] = n - u.partial(now)["XYZA".index(rest[0])]
            return []
        if c == "W":
            return self.cmd_w(rest)
        if c == "Y":
            if rest not in ("+", "&", "-"):
                raise CmdError(4)
            if rest in "+&" and u.moving():
                raise CmdError(7)
            u.mpg = rest                                   # [R22]
            if rest in "+&":
                u.st[6] |= B_RUN
            elif not u.queue:
                u.st[6] &= ~B_RUN
            return [body]
        if body == "K":
            if u.moving():
                raise CmdError(7)
            if u.kept is not None:
                raise CmdError(5)                          # [R18]
            u.kept = (u.queue, u.st[4], u.st[5], u.st[6])
            u.queue = []
            u.prof = None
            u.st[4] = u.st[5] = u.st[6] = 0
            return []
        if body == "R":
            if u.moving():
                raise CmdError(7)
            if u.kept is None:
                raise CmdError(5)                          # [R18]
            u.queue, u.st[4], u.st[5], u.st[6] = u.kept
            u.kept = None
            u.prof = None
            return []
        if body == "H":                                   # [R28] [R29]
            was_run = bool(u.st[6] & B_RUN)
            u.st[6] |= B_INTA | B_INTCOM
            if u.wref is not None:
                self.w_abort(now)
            if u.stop_ramp(now):
                u.halt_answer = True
                return 'deferred'
            if not was_run:
                u.st[6] &= ~B_RUN
            return []
        if body == "D":
            if u.moving():
                raise CmdError(7)
            u.queue = []
            u.prof = None
            u.st[4] = u.st[5] = u.st[6] = 0
            if u.mpg in "+&":
                u.st[6] |= B_RUN
            return []
        if body == "G":
            if not (u.st[6] & B_INTA):
                raise CmdError(6)                          # [R21]
            u.st[6] &= ~(B_INTA | B_INTCOM)
            u.st[4] = u.st[5] = 0
            if not u.queue:
                u.st[6] &= ~B_RUN
                raise CmdError(6)
            u.start_next(now)
            return []
        if body.startswith("EFR") or body.startswith("EUR") or body.startswith("ER"):
            k = 3 if body[1] in "FU" else 2
            a = parse_hex(body[k:], 0, 0xFF)
            if k == 2:
                return ["%02X" % u.eeprom[a]]
            if a > 252:
                raise CmdError(5)
            raw = bytes(u.eeprom[a:a + 4])
            if body[1] == "F":
                return [fmt_float(struct.unpack("<f", raw)[0])]  # [R20]
            return [struct.unpack("<I", raw)[0]]
        if body.startswith("EFW") or body.startswith("EUW") or body.startswith("EW"):
            k = 3 if body[1] in "FU" else 2
            parts = body[k:].split(",")
            if len(parts) != 2:
                raise CmdError(4)
            a = parse_hex(parts[0], 0, 0xFF)
            if k == 2:
                u.eeprom[a] = parse_hex(parts[1], 0, 0xFF)
                return []
            if a > 252:
                raise CmdError(5)
            if body[1] == "F":                             # [R39]
                try:
                    x = float(parts[1])
                    raw = struct.pack("<f", x)
                except (ValueError, OverflowError):
                    raise CmdError(4)
            else:
                raw = struct.pack("<I", parse_int(parts[1], 0, 0xFFFFFFFF))
            u.eeprom[a:a + 4] = raw
            return []
        if c == "O":
            parts = rest.split(",")
            if len(parts) != 2:
                raise CmdError(4)
            port = parse_int(parts[0], 0, 9)
            val = parse_hex(parts[1], 0, 0xFF)
            if port != 0:
                raise CmdError(5)
            u.outputs = val                                # [R23]
            return []
        if c == "I":
            port = parse_int(rest, 0, 9)
            if port not in (1, 2):
                raise CmdError(5)                          # [R24]
            return ["%02X" % u.inputs[port]]
        if body.startswith("SR"):                          # [R38]
            n = parse_int(body[2:], 0, 255)
            if n > 6:
                raise CmdError(5)
            return ["%02X" % u.st[n]]
        if body.startswith("SW"):
            parts = body[2:].split(",")
            if len(parts) != 2:
                raise CmdError(4)
            n = parse_int(parts[0], 0, 255)
            x = parse_hex(parts[1], 0, 0xFF)
            if n > 6:
                raise CmdError(5)
            u.st[n] = x
            u.check_interrupts(now)
            return []
        if body == "F":                                   # [R34]
            f = u.st[6] & ~B_QFULL
            if len(u.queue) >= QUEUE_MAX:
                f |= B_QFULL
            return ["%02X" % f]
        if body == "J":
            return 'J'
        raise CmdError(3)

    # ---- W reference run (13.6.7) [R25] --------------------------------
    def cmd_w(self, rest):
        u = self.unit
        if not rest or rest[0] not in "XYZA":
            raise CmdError(4)
        ax = "XYZA".index(rest[0])
        parts = rest[1:].split(",")
        if len(parts) != 4:
            raise CmdError(4)
        n2 = parse_int(parts[0])
        n3 = parse_int(parts[1], 1, u.rate)
        n4 = parse_int(parts[2], 0, MAXV)
        n5 = parse_int(parts[3], 1, u.rate)
        if u.moving() or u.queue or u.mpg in "+&":
            raise CmdError(7)
        direction = 1 if n2 >= 0 else -1
        ph = u.phys(self.now)[ax]
        sw = u.switches[ax]
        found = False
        d1 = n2
        if sw is not None:
            dist = (sw - ph) * direction
            if 0 <= dist <= abs(n2):
                found = True
                d1 = dist * direction
        else:
            bit = 1 << ax
            if not (u.inputs[1] & bit):                # reference input active (0) [R25]
                found = True
                d1 = 0
        d2 = 1 if found else 0
        d2 = min(d2, n4)
        t1 = self.now + int(math.ceil(abs(d1) * 1e9 / n3))
        t2 = t1 + int(math.ceil(d2 * 1e9 / n5))
        u.wref = {'axis': ax, 'dir': direction, 'd1': d1, 'd2': d2, 'v1': n3, 'v2': n5,
                  't0': self.now, 't1': t1, 't2': t2, 'found': found}
        u.st[6] |= B_RUN
        self.pending.append((t2, 'W'))
        return 'deferred'

    def w_end(self, now, aborted=False):
        u = self.unit
        w = u.wref
        delta = [0, 0, 0, 0]
        delta[w['axis']] = u.wref_partial(now)[w['axis']]
        u.wref = None
        u.move_commit(delta)
        if w['found'] and not aborted:
            u.counter[w['axis']] = 0                    # W zeroes the axis counter
        u.st[6] &= ~B_RUN
        self.pending = [p for p in self.pending if p[1] != 'W']
        if not aborted:
            self.answer(0 if w['found'] else 5)         # [R25]

    def w_abort(self, now):
        self.w_end(now, aborted=True)

    # ---- restart (J, power-on) -----------------------------------------
    def restart(self):
        u = self.unit
        if u.queue and u.prof is not None:
            u.replan_base(self.now)                     # axes stop where they are
        if u.wref is not None:
            self.w_end(self.now, aborted=True)
        u.reset_state(self.now)
        self.pending = []
        self.rxbuf = None
        self.wd_deadline = None
        self.deaf_until = self.now + RESTART_NS
        self.to_host = [(t, c) for (t, c) in self.to_host if t <= self.tx_free and
                        t <= self.now + 10 * self.b or True]
        # rate switch read at power-on [R27]
        if u.rate_position is not None:
            tab = RATES_01 if u.eeprom[0x0D] == 0x01 else RATES_FF
            u.rate_read = tab[u.rate_position]
        else:
            u.rate_read = None
        # 11.2: an output set up as brake (0x08) switches on FD*0.1 s (max 5 s)
        # after power comes on [R26]
        if any(u.eeprom[a] == 0x08 for a in (1, 2, 3)):
            delay = min(u.eeprom[0xFD], 50) * 100_000_000
            self.pending.append((self.deaf_until + delay, 'BRAKE'))

    # ---- event loop ----------------------------------------------------
    def next_unit_event(self):
        u = self.unit
        cands = []
        if self.wd_deadline is not None:
            cands.append(self.wd_deadline)
        if self.deaf_until is not None:
            cands.append(self.deaf_until)
        m = u.motion_event_time()
        if m is not None:
            cands.append(m)
        for t, _ in self.pending:
            cands.append(t)
        return min(cands) if cands else None

    def unit_event(self, t):
        u = self.unit
        if self.deaf_until is not None and self.deaf_until <= t:
            self.deaf_until = None
        if self.wd_deadline is not None and self.wd_deadline <= t:
            self.watchdog()
        m = u.motion_event_time()
        if m is not None and m <= t:
            if u.motion_event(t) == 'H':
                self.answer(0)
        for p in list(self.pending):
            if p[0] <= t and p[1] == 'W' and u.wref is not None:
                self.w_end(t)
            elif p[0] <= t and p[1] == 'BRAKE':
                self.pending.remove(p)
                for a, bit in ((1, 0x04), (2, 0x08), (3, 0x02)):   # 13.6.11 bit map
                    if u.eeprom[a] == 0x08:
                        u.outputs &= ~bit

    def advance(self, limit, cr_stop):
        """returns (list of (t, byte) reported, stopped_at_cr)"""
        out = []
        while True:
            cands = []
            ue = self.next_unit_event()
            if ue is not None:
                cands.append((ue, 0))
            if self.to_host:
                cands.append((self.to_host[0][0], 1))
            if self.to_unit:
                cands.append((self.to_unit[0][0], 2))
            if not cands:
                self.now = limit
                return out, False
            t, kind = min(cands)
            if t > limit:
                self.now = limit
                return out, False
            self.now = max(self.now, t)
            if kind == 0:
                self.unit_event(t)
            elif kind == 1:
                _, c = self.to_host.pop(0)
                out.append((t, c))
                if c == 0x0D and cr_stop:
                    return out, True
            else:
                _, c = self.to_unit.pop(0)
                self.rx_byte(c)

    def next_event(self):
        cands = []
        ue = self.next_unit_event()
        if ue is not None:
            cands.append(ue)
        if self.to_host:
            cands.append(self.to_host[0][0])
        if self.to_unit:
            cands.append(self.to_unit[0][0])
        cands = [c for c in cands if c > self.now] or ([self.now + 1] if cands else [])
        return min(cands) if cands else None

    # ---- rig (rig.md) --------------------------------------------------
    def state(self):
        u = self.unit
        st = list(u.st)
        return {"profile": u.model, "addresses": [u.address],
                "position": u.pos(self.now), "physical": u.phys(self.now),
                "excursion": [list(e) for e in u.excursion],
                "status": ["%02X" % x for x in st],
                "outputs": "%02X" % u.outputs, "spindle": u.spindle,
                "inputs": {str(k): "%02X" % v for k, v in sorted(u.inputs.items())},
                "rate_position": u.rate_position, "rate": u.rate_read,
                "time_ns": self.now, "queue": len(u.queue), "index": u.index,
                "checksums": u.checksums,
                "modal": {"V": u.V, "A": u.A, "B": u.B, "$": u.short, "T": u.T,
                          "VK": u.VK, "VL": u.VL, "XM": u.XM},
                "mpg": u.mpg, "kept": u.kept is not None,
                "packet_open": u.packet is not None}

    def power_on(self):
        self.restart()
        # an answer due later (H, W) is never sent; bytes already queued complete


def fmt_float(x):
    if math.isnan(x) or math.isinf(x):
        return "nan" if math.isnan(x) else ("inf" if x > 0 else "-inf")
    return ("%.6g" % x)


def num(s):
    if not s or len(s) > 20 or not all(ch in "0123456789" for ch in s):
        raise ValueError("bad number")
    return int(s)


def main():
    args = sys.argv[1:]
    model, address, baud, cosim = "GVE114-500", 0, 115200, False
    i = 0
    while i < len(args):
        a = args[i]
        if a == "--cosim":
            cosim = True
        elif a == "--model":
            i += 1; model = args[i]
        elif a == "--address":
            i += 1; address = int(args[i])
        elif a == "--baud":
            i += 1; baud = int(args[i])
        else:
            sys.stderr.write("unknown argument %s\n" % a)
            sys.exit(2)
        i += 1
    if model not in MODELS or not 0 <= address <= 7:
        sys.stderr.write("bad model/address\n")
        sys.exit(2)
    if not cosim:
        sys.stderr.write("only --cosim (virtual time) is offered\n")
        sys.exit(2)
    sim = Sim(model, address, baud)
    out = sys.stdout
    out.write("cosim 1 batch batch-stops pipeline snapshot\n")
    out.flush()

    def rxlines(lst):
        return ["rx %d %02X" % (t, c) for t, c in lst]

    def do_tx(hexs, T=None):
        if len(hexs) % 2 or not hexs or any(ch not in "0123456789abcdefABCDEF" for ch in hexs):
            raise ValueError("bad hex")
        data = bytes.fromhex(hexs)
        end = sim.now + len(data) * sim.b
        if T is not None and T < end:
            raise ValueError("T before the bytes' end")
        t = sim.now
        for c in data:
            t += sim.b
            sim.to_unit.append((t, c))
        got, _ = sim.advance(end, False)
        cr = any(c == 0x0D for _, c in got)
        if T is not None and not cr:
            more, _ = sim.advance(T, True)
            got += more
        return rxlines(got) + ["now %d" % sim.now], cr

    for line in sys.stdin:
        line = line.rstrip("\n").rstrip("\r")
        w = line.split()
        if not w:
            continue
        rep = []
        try:
            cmd = w[0]
            if w[-1].startswith("@") and cmd in ("in", "switch", "state", "power-on", "rate"):
                if num(w[-1][1:]) != sim.unit.address:
                    raise ValueError("no unit at that address")
                w = w[:-1]
            if cmd in ("quit", "exit"):
                break
            elif cmd == "tx" and len(w) in (2, 3):
                T = num(w[2]) if len(w) == 3 else None
                rep, _ = do_tx(w[1], T)
            elif cmd == "batch" and len(w) >= 3 and len(w) % 2 == 1:
                pairs = [(num(w[k]), w[k + 1]) for k in range(1, len(w), 2)]
                for _, h in pairs:
                    if len(h) % 2 or not h or any(ch not in "0123456789abcdefABCDEF" for ch in h):
                        raise ValueError("bad hex")
                for D, h in pairs:
                    end = sim.now + len(h) // 2 * sim.b
                    r, cr = do_tx(h, end + D)
                    rep += r
                    if not any(x.startswith("rx") and x.endswith(" 0D") for x in r):
                        break
            elif cmd == "until" and len(w) == 2:
                T = num(w[1])
                if T < sim.now:
                    raise ValueError("until before now")
                got, _ = sim.advance(T, True)
                rep = rxlines(got) + ["now %d" % sim.now]
            elif cmd == "next" and len(w) == 1:
                n = sim.next_event()
                rep = ["next none" if n is None else "next %d" % n]
            elif cmd == "baud" and len(w) == 2:
                n = num(w[1])
                if n <= 0:
                    raise ValueError("bad rate")
                sim.baud = n
                nb = round(1e10 / n)
                # bytes not yet begun take the new time
                new, t = [], None
                for (tc, c) in sim.to_host:
                    if tc - sim.b <= sim.now:
                        new.append((tc, c)); t = tc
                    else:
                        t = (t if t is not None else sim.now) + nb
                        new.append((t, c))
                sim.to_host = new
                if new:
                    sim.tx_free = new[-1][0]
                sim.b = nb
                rep = ["ok"]
            elif cmd == "in" and len(w) == 3:
                port = num(w[1])
                if port > 2 or len(w[2]) != 2:
                    raise ValueError("bad port")
                sim.unit.inputs[port] = int(w[2], 16)
                sim.unit.check_interrupts(sim.now)
                rep = ["ok"]
            elif cmd == "switch" and len(w) == 3 and w[1] in ("X", "Y", "Z", "A"):
                ax = "XYZA".index(w[1])
                if w[2] == "none":
                    sim.unit.switches[ax] = None
                else:
                    s = w[2]
                    sign = -1 if s[0] == "-" else 1
                    if s[0] in "+-":
                        s = s[1:]
                    sim.unit.switches[ax] = sign * num(s)
                rep = ["ok"]
            elif cmd == "rate" and len(w) == 2:
                if w[1] == "none":
                    sim.unit.rate_position = None
                else:
                    p = num(w[1])
                    if p > 3:
                        raise ValueError("no such position")
                    sim.unit.rate_position = p
                rep = ["ok"]
            elif cmd == "power-on" and len(w) == 1:
                sim.power_on()
                rep = ["ok"]
            elif cmd == "state" and len(w) == 1:
                rep = [json.dumps(sim.state())]
            elif cmd == "snapshot" and len(w) == 1:
                sim.snap = copy.deepcopy({k: v for k, v in sim.__dict__.items() if k != 'snap'})
                rep = ["ok"]
            elif cmd == "restore" and len(w) == 1:
                if sim.snap is None:
                    raise ValueError("no snapshot taken")
                now, b, baud = sim.now, sim.b, sim.baud
                keep = sim.snap
                shift = now - keep['now']
                sim.__dict__.update(copy.deepcopy(keep))
                sim.snap = keep
                # the unit stood untouched from the snapshot to now: advance it
                sim.now = keep['now']
                sim.advance(now, False)
                sim.now = now
                rep = ["now %d" % now]
            elif cmd == "help":
                rep = ["commands: tx HEX [T] | batch D HEX ... | until T | next | baud N | "
                       "in PORT HEX | switch AXIS POS|none | rate POS|none | power-on | state | "
                       "snapshot | restore | quit"]
            else:
                raise ValueError("unknown command %r" % line)
        except (ValueError, IndexError, KeyError) as e:
            rep = ["error: %s" % e]
        out.write("\n".join(rep) + "\n")
        out.flush()


if __name__ == "__main__":
    main()
