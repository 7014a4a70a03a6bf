#!/usr/bin/env python3
"""GVE84 (Gravos HW interpolator) simulator, written from the vendor's manual
(given/GVE84-manual.txt, chapter 12) and driven over the co-simulation protocol
of given/cosim.md with the test rig of given/rig.md.

Structure:
  Motion   - the vector queue and the step-by-step motion in virtual time
  Unit     - the firmware: receiver/framing/watchdog, commands, answers, status
  CoSim    - the virtual clock, the serial line in both directions, the rig

[Rn] refers to READINGS.md.  Standard library only.
"""
import json
import math
import sys

NS = 1_000_000_000
VERSION = "IP84 v3 27.1.2010"          # manual 12.2; answer of '?'  [R47]
CPU_ID = "25020304"                    # manual 12.5.1 example  [R3]
MODELS = {"GVE84-15": 15000, "GVE84-50": 50000, "GVE84-100": 100000}   # [R1]
AXES = "XYZ"
QUEUE_SIZE = 64                        # [R10]
WATCHDOG_NS = 100_000_000              # [R5]
RESTART_NS = 2_000_000_000             # manual 12.4 "cca po 2s"
MAX_FRAME = 64                         # [R6]
I32 = 2147483647

# ST6 bits (manual 12.5.11)
STOP, FREE, INTCOM, RUN, INTA = 0x01, 0x02, 0x10, 0x40, 0x80   # [R38]
QFULL = 0x20                           # F only


def isqrt0(x):
    return math.sqrt(x) if x > 0 else 0.0


# ----------------------------------------------------------------------------
# Motion
# ----------------------------------------------------------------------------
class Vec:
    """One queued vector.  Rates are in steps/s of its major (longest) axis."""

    def __init__(self, d, cont, v, a, b, short, vk):
        self.d = d                          # (dx, dy, dz) relative [manual 12.5.2]
        self.cont = cont                    # C vector?
        self.L = max(abs(x) for x in d)     # major-axis steps
        self.v = v                          # stored speed (XA/XU/XD change it)
        self.a = a                          # steps/s^2
        self.b = b                          # brake speed to a following C
        self.short = self.L < short         # [manual $]
        # VK: speeds along the path; convert to major-axis rate [R17]
        dist = math.sqrt(sum(x * x for x in d))
        self.k = (self.L / dist) if (vk and dist > 0) else 1.0
        self.s = 0.0                        # progress in major steps

    def steps_at(self, s):
        """Per-axis counter offset after progress s (Bresenham rounding) [R18]."""
        if self.L == 0:
            return (0, 0, 0)
        n = min(self.L, int(math.floor(s + 1e-6)))
        out = []
        for x in self.d:
            m = (n * abs(x) + self.L // 2) // self.L
            out.append(m if x >= 0 else -m)
        return tuple(out)


class Motion:
    def __init__(self, unit):
        self.u = unit
        self.q = []              # vectors, q[0] is the one executing
        self.base = [0, 0, 0]    # physical position at the start of q[0]
        self.v = 0.0             # speed at plan anchor
        self.phases = []         # (t0, t1, s0, v0, a) absolute ns floats
        self.t_end = None        # float ns when the plan ends (vector end/stop)
        self.stopping = False    # stop ramp (H, interrupt, SW6) in progress
        self.moving = False      # a plan is active (axes may move)
        self.last_stop = 0       # instant motion last came to rest [R13]
        self.exc = [[0, 0] for _ in range(3)]

    # -- evaluation ----------------------------------------------------------
    def state_at(self, t):
        """(s, v) of the head vector at instant t."""
        if not self.moving or not self.q:
            return (self.q[0].s if self.q else 0.0), 0.0
        ph = self.phases
        if not ph or t <= ph[0][0]:
            return self.q[0].s, (ph[0][3] if ph else 0.0)
        for (t0, t1, s0, v0, a) in ph:
            if t <= t1:
                dt = (t - t0) / NS
                return s0 + v0 * dt + 0.5 * a * dt * dt, max(0.0, v0 + a * dt)
        t0, t1, s0, v0, a = ph[-1]
        dt = (t1 - t0) / NS
        return s0 + v0 * dt + 0.5 * a * dt * dt, max(0.0, v0 + a * dt)

    def physical(self, t):
        if not self.q:
            return list(self.base)
        s, _ = self.state_at(t)
        off = self.q[0].steps_at(min(s, self.q[0].L))
        p = [self.base[i] + off[i] for i in range(3)]
        self.note(p)
        return p

    def note(self, p):
        for i in range(3):
            self.exc[i][0] = min(self.exc[i][0], p[i])
            self.exc[i][1] = max(self.exc[i][1], p[i])

    # -- rates ---------------------------------------------------------------
    def target(self, vec):
        """Cruise rate of vec in its major-axis steps/s [R15][R16][R17]."""
        u = self.u
        r = vec.v * u.xm / 100.0 * vec.k
        if vec.short:
            r = min(r, vec.b * vec.k)
        for i in range(3):
            if vec.d[i]:
                lim = min(u.vl[i], u.maxrate) * vec.L / abs(vec.d[i])
                r = min(r, lim)
        return max(r, 1.0)

    def end_limits(self):
        """Braking map: allowed speed at the end of every queued vector [R14]."""
        n = len(self.q)
        ve = [0.0] * n
        for k in range(n - 2, -1, -1):
            a, b = self.q[k], self.q[k + 1]
            if not b.cont:
                continue
            j = min(a.b * a.k, self.target(a), self.target(b))
            ve[k] = min(j, math.sqrt(ve[k + 1] ** 2 + 2 * b.a * b.k * (b.L - b.s)))
        return ve

    # -- planning ------------------------------------------------------------
    def plan(self, now, start=None):
        """(Re)plan the head vector from its state at `now` (or from rest at `start`)."""
        if not self.q:
            self.moving = False
            self.phases = []
            self.t_end = None
            return
        vec = self.q[0]
        if start is None and self.moving and now < self.t_start:
            start = self.t_start            # still in the dwell before it
        if start is not None:
            s, v, t = vec.s, 0.0, float(start)
        else:
            s, v = self.state_at(now)
            t = float(now)
            vec.s = s
        self.t_start = t
        A = vec.a * vec.k
        d = max(0.0, vec.L - s)
        ph = []

        def add(dist, v0, a):
            nonlocal t, s
            if dist <= 1e-12:
                return v0
            if a == 0:
                dt = dist / v0
                v1 = v0
            else:
                v1 = isqrt0(v0 * v0 + 2 * a * dist)
                dt = (v1 - v0) / a
            ph.append((t, t + dt * NS, s, v0, a))
            t += dt * NS
            s += dist
            return v1

        if self.stopping:
            add(min(d, v * v / (2 * A)), v, -A)    # to rest, or on into the next [R21]
        else:
            vt = self.target(vec)
            ve = self.end_limits()[0]
            if v <= vt + 1e-9:
                xm = (ve * ve - v * v + 2 * A * d) / (4 * A)
                if xm <= 0:
                    add(d, v, -A)
                elif xm >= d:
                    add(d, v, A)                # still below the braking map at the end
                else:
                    vp = isqrt0(v * v + 2 * A * xm)
                    if vp <= vt:
                        w = add(xm, v, A)
                        add(d - xm, w, -A)
                    else:
                        xa = (vt * vt - v * v) / (2 * A)
                        xb = (vt * vt - ve * ve) / (2 * A)
                        xb = min(xb, d)
                        xa = min(xa, d - xb)
                        add(xa, v, A)
                        add(d - xa - xb, vt, 0)
                        add(xb, vt, -A)
            else:
                if (v * v - ve * ve) / (2 * A) <= d:
                    x1 = (v * v - vt * vt) / (2 * A)
                    xb = (vt * vt - ve * ve) / (2 * A)
                    add(x1, v, -A)
                    add(d - x1 - xb, vt, 0)
                    add(xb, vt, -A)
                else:
                    add(d, v, -A)
        self.phases = ph
        self.t_end = t
        self.moving = True

    def replan_if_moving(self, now):
        """A rate changed (XA, XU, XD, XM, VL): the running vector follows at A."""
        if self.moving and not self.stopping:
            self.plan(now)

    def next_time(self):
        if self.moving and self.t_end is not None:
            return int(math.ceil(self.t_end - 1e-6))
        return None

    # -- events --------------------------------------------------------------
    def may_run(self):
        return not self.u.st[6] & INTA

    def start_if_idle(self, now):
        """Start the head vector if the unit may move and nothing is planned."""
        if self.moving or not self.q or not self.may_run():
            return
        vec = self.q[0]
        start = now
        if not vec.cont and vec.s == 0:                 # also L0,0,0 [R45]
            start = max(now, self.last_stop + self.u.t_dwell * 1_000_000)  # [R13]
        self.stopping = False
        self.plan(now, start=start)

    def event(self, now):
        """The plan's end has come: a vector ended or a stop ramp ended."""
        vec = self.q[0]
        s, v = self.state_at(now)
        if self.stopping:
            if s >= vec.L - 1e-6:
                self.finish_head()
                if v > 1e-6 and self.q:
                    # the ramp runs on into the next vector [R21]
                    self.q[0].s = 0.0
                    self.phases = [(now, now, 0.0, v, 0.0)]
                    self.plan(now)
                    return
            else:
                vec.s = s
            self.come_to_rest(now)
            return
        self.finish_head()
        if self.q and self.q[0].cont and v > 1e-6:
            self.phases = [(now, now, 0.0, v, 0.0)]
            self.plan(now)
            return
        self.moving = False
        self.phases = []
        self.t_end = None
        self.last_stop = now
        self.start_if_idle(now)

    def finish_head(self):
        vec = self.q.pop(0)
        for i in range(3):
            self.base[i] += vec.d[i]
        self.note(self.base)

    def come_to_rest(self, now):
        if self.q and 0 < self.q[0].s < self.q[0].L:
            # keep the rest of the halted vector as a vector of its own  [R21]
            vec = self.q[0]
            off = vec.steps_at(vec.s)
            self.base = [self.base[i] + off[i] for i in range(3)]
            rest = Vec(tuple(vec.d[i] - off[i] for i in range(3)), vec.cont,
                       vec.v, vec.a, vec.b, 0, False)
            rest.short, rest.k = vec.short, vec.k
            self.q[0] = rest
            if rest.L == 0:
                self.q.pop(0)
        self.moving = False
        self.stopping = False
        self.phases = []
        self.t_end = None
        self.last_stop = now
        self.u.st[6] &= ~STOP & 0xFF
        self.u.motion_stopped(now)

    def halt(self, now):
        """Begin a stop ramp (H, interrupt, SW6 INTA) [manual 12.5.8 H]."""
        if not self.moving:
            return False
        s, v = self.state_at(now)
        if now < (self.phases[0][0] if self.phases else now) or v <= 1e-9:
            # still in the dwell before the vector, or at rest: stop at once
            self.q[0].s = s
            self.come_to_rest(now)
            return False
        self.stopping = True
        self.u.st[6] |= STOP
        self.plan(now)
        return True

    def freeze(self, now):
        """Power gone (J, power-on): the axes stop where they are."""
        self.base = self.physical(now)
        self.q = []
        self.moving = False
        self.stopping = False
        self.phases = []
        self.t_end = None
        self.last_stop = now


# ----------------------------------------------------------------------------
# The unit (firmware)
# ----------------------------------------------------------------------------
class Unit:
    def __init__(self, model, address, baud, sim):
        self.sim = sim
        self.model = model
        self.maxrate = MODELS[model]
        self.address = address
        self.baud = baud                    # the rate the unit was ordered with
        self.eeprom = [0xFF] * 256          # [R30]
        self.eeprom[0x01] = 0x00            # relay = spindle (manual 11)
        self.eeprom[0x05] = 0xFF            # STEP/DIR polarity default (11.3)
        self.inputs = [0xFF, 0xFF, 0xFF]
        self.switch = [None, None, None]
        self.m = Motion(self)
        self.reset(0, restart=False)

    # -- reset state (manual 12.4) --------------------------------------------
    def reset(self, now, restart=True):
        self.st = [0] * 7
        self.a = 20000
        self.v = 1000
        self.short = 512
        self.b = self.maxrate               # [R8] B35000 "pro 35000 hz verzi"
        self.t_dwell = 5                    # [R12]
        self.vk = False                     # [R17]
        self.vl = [self.maxrate] * 3        # [R16]
        self.xm = 100
        self.outputs = 0xFF
        self.cs = False
        self.index = 0
        self.last_answer = None
        self.kept = None
        self.packet = None
        self.frame = None
        self.frame_deadline = None
        self.pending = None                 # 'H' or a W run awaiting its answer
        if getattr(self, "wrun", None):
            self.m.base = self.wrun_pos(now)
        self.wrun = None
        self.m.freeze(now)
        self.m.last_stop = now + (RESTART_NS if restart else 0)
        self.offset = list(self.m.base)     # counters = physical - offset (N)
        self.deaf_until = now + RESTART_NS if restart else None

    def counters(self, now):
        p = self.physical(now)
        return [p[i] - self.offset[i] for i in range(3)]

    def physical(self, now):
        if self.wrun:
            return self.wrun_pos(now)
        return self.m.physical(now)

    def running(self):
        """'Za chodu': axes moving or a stop ramp or a W run  [R22]."""
        return self.m.moving or self.wrun is not None

    def st6(self):
        s = self.st[6] & ~RUN & 0xFF
        if self.m.q or self.wrun:
            s |= RUN
        return s

    # -- time ------------------------------------------------------------------
    def next_event(self):
        c = []
        if self.deaf_until is not None:
            c.append(self.deaf_until)
        if self.frame_deadline is not None:
            c.append(self.frame_deadline)
        t = self.m.next_time()
        if t is not None:
            c.append(t)
        if self.wrun:
            c.append(self.wrun["t_end"])
        return min(c) if c else None

    def process(self, now):
        """Run the unit's own events due at `now` (before a byte at `now`)."""
        if self.deaf_until is not None and now >= self.deaf_until:
            self.deaf_until = None
        if self.frame_deadline is not None and now >= self.frame_deadline:
            # watchdog: the frame did not come whole in time  [R5]
            fr = self.frame
            self.frame = None
            self.frame_deadline = None
            if fr is not None and len(fr) >= 2 and fr[1] == ord(str(self.address)):
                self.answer(now, 2)
        t = self.m.next_time()
        if t is not None and now >= t:
            self.m.event(now)
        if self.wrun and now >= self.wrun["t_end"]:
            self.wrun_step(now)

    # -- receiver ----------------------------------------------------------------
    def receive(self, now, byte):
        if self.deaf_until is not None:
            return                          # restarting: bytes are lost
        if byte == 0x21:                    # '!' always begins a frame [R6]
            self.frame = bytearray(b"!")
            self.frame_deadline = now + WATCHDOG_NS
            return
        if self.frame is None:
            return                          # noise between frames
        if byte == 0x0D:
            fr = bytes(self.frame)
            self.frame = None
            self.frame_deadline = None
            self.on_frame(now, fr)
            return
        self.frame.append(byte)
        self.frame_deadline = now + WATCHDOG_NS
        if len(self.frame) > MAX_FRAME + 8:
            self.frame = self.frame[:MAX_FRAME + 8]

    def answer(self, now, code, *params):
        """Hand an answer to the transmitter at once (12.6 "ihned") [R2]:
        one hex digit INTA<<3 | error code, the parameters, the checksum [R7]."""
        s = "%X" % ((code & 7) | (8 if self.st[6] & INTA else 0))
        for p in params:
            s += "," + str(p)
        if self.cs:
            s += ",%02X" % (sum((s + ",").encode()) & 0xFF)
        self.last_answer = s
        self.sim.send(now, (s + "\r").encode("latin-1"))

    # -- frames ------------------------------------------------------------------
    def on_frame(self, now, fr):
        if len(fr) < 2 or fr[1] != ord(str(self.address)):
            return                          # another unit's frame [R4]
        if self.pending is not None:
            return                          # busy awaiting H/W  [R26]
        body = fr[2:].decode("latin-1")
        if len(fr) > MAX_FRAME:
            self.answer(now, 4)
            return
        if self.cs:
            cut = body.rfind(",")
            if cut < 0 or not _ishex(body[cut + 1:]) or not 1 <= len(body) - cut - 1 <= 2:
                self.answer(now, 4)         # [R7]
                return
            want = int(body[cut + 1:], 16)
            got = sum(fr[:2 + cut + 1]) & 0xFF
            if want != got:
                self.answer(now, 4)
                return
            body = body[:cut]
        if body == "@":
            self.answer(now, 0, self.index)           # [R24]
            return
        if body == ">":
            if self.last_answer is None:
                self.answer(now, 0)
            else:
                self.sim.send(now, (self.last_answer + "\r").encode("latin-1"))  # [R25]
            return
        self.index = (self.index + 1) & 0xFF
        if self.packet is not None and body[:2] != "*E" and body[:2] != "*S":
            self.packet.append(body)                  # [R27]
            return
        self.execute(now, body)

    # -- commands ----------------------------------------------------------------
    def execute(self, now, c):
        try:
            res = self.dispatch(now, c)
        except Err as e:
            res = (e.code,)
        if res is not None:
            self.answer(now, *res)
        self.check_interrupts(now)

    def dispatch(self, now, c):
        m = self.m
        if c == "?":
            return (0, VERSION)
        if c == "Q":
            return (0, CPU_ID)
        if c == "%+":
            self.cs = True
            return (0,)
        if c == "%-":
            self.cs = False
            return (0,)
        if c == "*S":
            self.packet = []
            return None                                # answered at *E [R27]
        if c.startswith("*E"):
            return self.packet_end(now, c[2:])
        if c[:1] in "LC" and c[:1] != "":
            return self.vector(now, c[0], c[1:])
        if c.startswith("VL"):
            p = nums(c[2:], 3, 4)
            for x in p:
                rng(x, 10, 100000)                    # [R16]
            self.vl = [min(x, self.maxrate) for x in p[:3]]
            m.replan_if_moving(now)
            return (0,)
        if c == "VK":
            self.vk = True
            return (0,)
        if c == "VN":
            self.vk = False
            return (0,)
        if c.startswith("V"):
            self.v = rng(num1(c[1:]), 10, self.maxrate)   # [R9]
            return (0,)
        if c.startswith("A"):
            self.a = rng(num1(c[1:]), 1, 65535) * 1000     # [R11]
            return (0,)
        if c.startswith("B"):
            self.b = rng(num1(c[1:]), 10, 100000)
            return (0,)
        if c.startswith("T"):
            self.t_dwell = rng(num1(c[1:]), 1, 24)
            return (0,)
        if c.startswith("$"):
            self.short = rng(num1(c[1:]), 1, I32)
            return (0,)
        if c in ("XA", "XU", "XD"):
            for vec in m.q:                              # [R19]
                if c == "XA":
                    vec.v = self.v
                elif c == "XU":
                    vec.v = min(self.maxrate, vec.v + vec.v / 16.0)
                else:
                    vec.v = max(10, vec.v - vec.v / 16.0)
            m.replan_if_moving(now)
            return (0,)
        if c.startswith("XM"):
            self.xm = rng(num1(c[2:]), 1, 1000)          # [R20]
            m.replan_if_moving(now)
            return (0,)
        if c == "P":
            p = self.counters(now)
            return (0, p[0], p[1])
        if c == "PF":
            p = self.counters(now)
            return (0, p[0], p[1], p[2])
        if c == "N":
            if self.st6() & RUN:
                return (7,)
            self.offset = self.physical(now)
            return (0,)
        if c[:1] == "N" and len(c) >= 2:
            ax = axis(c[1])
            val = rng(num1(c[2:]), -I32, I32)
            if self.st6() & RUN:
                return (7,)                               # [R23]
            self.offset[ax] = self.physical(now)[ax] - val
            return (0,)
        if c.startswith("W"):
            return self.reference(now, c[1:])
        if c == "K":
            if self.running():
                return (7,)
            if self.kept is not None:
                return (5,)                               # [R28]
            self.kept = (m.q, self.st[4], self.st[5], self.st[6])
            m.q = []
            self.st[4] = self.st[5] = self.st[6] = 0
            return (0,)
        if c == "R":
            if self.running():
                return (7,)
            if self.kept is None:
                return (5,)
            q, self.st[4], self.st[5], self.st[6] = self.kept
            self.kept = None
            m.q = q                                     # [R28]
            m.start_if_idle(now)
            return (0,)
        if c == "H":
            self.st[6] |= INTA | INTCOM
            if m.halt(now):
                self.pending = "H"                      # answered at rest
                return None
            return (0,)                                   # at rest: at once [R42]
        if c == "D":
            if self.running():
                return (7,)
            m.q = []
            self.st[4] = self.st[5] = self.st[6] = 0
            return (0,)
        if c == "G":
            if not self.st[6] & INTA:
                return (6,)                               # [R29]
            self.st[6] &= ~(INTA | INTCOM) & 0xFF
            self.st[4] = self.st[5] = 0
            if not m.q:
                return (6,)
            m.start_if_idle(now)
            return (0,)
        if c.startswith("ER"):
            a = hexn(c[2:])
            return (0, "%02X" % self.eeprom[a])
        if c.startswith("EW"):
            p = c[2:].split(",")
            if len(p) != 2:
                raise Err(4)
            a, x = hexn(p[0]), hexn(p[1])
            self.eeprom[a] = x
            return (0,)
        if c.startswith("O"):
            p = c[1:].split(",")
            if len(p) != 2:
                raise Err(4)
            port, x = num1(p[0]), hexn(p[1])
            if port != 0:
                return (5,)
            self.outputs = x                              # [R39][R40]
            return (0,)
        if c.startswith("I"):
            port = num1(c[1:])
            if port != 1:
                return (5,)                               # [R31]
            return (0, "%02X" % self.inputs[1])
        if c.startswith("SR"):
            n = num1(c[2:])
            rng(n, 0, 6)
            return (0, "%02X" % (self.st6() if n == 6 else self.st[n]))
        if c.startswith("SW"):
            p = c[2:].split(",")
            if len(p) != 2:
                raise Err(4)
            n, x = num1(p[0]), hexn(p[1])
            rng(n, 0, 6)
            if n == 6:
                return self.write_st6(now, x)
            self.st[n] = x                                # [R41][R46]
            return (0,)
        if c == "F":
            s = self.st6()
            if len(m.q) >= (1 if self.kept is not None else QUEUE_SIZE):
                s |= QFULL
            return (0, "%02X" % s)
        if c == "J":
            self.answer(now, 0)
            self.reset(now)                               # [R32]
            return None
        raise Err(3)                                      # [R44]

    def write_st6(self, now, x):
        """SW6: raw write of the flags; RUN reflects the queue [R33]."""
        was = self.st[6] & INTA
        self.st[6] = x & ~RUN & 0xFF
        if (x & INTA) and not was:
            self.m.halt(now)
        elif was and not (x & INTA):
            self.m.start_if_idle(now)
        return (0,)

    def vector(self, now, kind, args, dry=False):
        p = nums(args, 3, 3)
        for x in p:
            rng(x, -I32, I32)
        vec = Vec(tuple(p), kind == "C", self.v, self.a, self.b, self.short, self.vk)
        if dry:
            return vec
        return self.enqueue(now, [vec])

    def enqueue(self, now, vecs):
        m = self.m
        cap = 1 if self.kept is not None else QUEUE_SIZE
        for vec in vecs:
            if not vec.cont and (m.q or len(vecs) > 1):
                return (1,)                               # [R10] L only into an empty queue
            if vec.cont and self.kept is not None:
                return (1,)                               # [R28] KEEP: L only
        if len(m.q) + len(vecs) > cap:
            return (1,)
        m.q.extend(vecs)
        if m.moving and not m.stopping:
            m.plan(now)
        else:
            m.start_if_idle(now)
        return (0,)

    def packet_end(self, now, arg):
        pk = self.packet
        if pk is None:
            return (4,)                                   # [R27]
        self.packet = None
        n = num1(arg)
        if n != len(pk):
            return (2, len(pk))
        vecs = []
        for c in pk:
            try:
                if c[:1] == "C":
                    vecs.append(self.vector(now, "C", c[1:], dry=True))
                elif c[:1] == "B":
                    self.b = rng(num1(c[1:]), 10, 100000)
                else:
                    return (3, len(pk))
            except Err as e:
                return (e.code, len(pk))
        res = self.enqueue(now, vecs) if vecs else (0,)
        return (res[0], len(pk))

    # -- W reference run (manual 12.5.7) [R34] ------------------------------------
    def reference(self, now, args):
        p = args.split(",")
        if len(p) != 5:
            raise Err(4)
        ax = axis(p[0])
        n2, n3, n4, n5 = (num1(x) for x in p[1:])
        rng(n2, -I32, I32)
        if n2 == 0:
            raise Err(5)
        rng(n3, 10, self.maxrate)
        rng(n4, 0, I32)
        rng(n5, 10, self.maxrate)
        if self.running():
            return (7,)
        start = self.m.physical(now)
        self.wrun = {"ax": ax, "dir": 1 if n2 > 0 else -1, "phase": 1,
                     "p0": start[ax], "pos": start, "t0": now, "rate": n3,
                     "max": abs(n2), "back": n4, "rate2": n5}
        self.pending = "W"
        self.wrun_plan(now)
        return None

    def ref_active(self, w, pos):
        sw = self.switch[w["ax"]]
        if sw is not None:
            return pos == sw
        return not (self.inputs[1] >> w["ax"]) & 1      # REF input grounded

    def wrun_plan(self, now):
        """Compute how many steps the current phase takes and when it ends."""
        w = self.wrun
        d = w["dir"] if w["phase"] == 1 else -w["dir"]
        lim = w["max"] if w["phase"] == 1 else w["back"]
        sw = self.switch[w["ax"]]
        p0 = w["p0"]
        if w["phase"] == 1:
            if sw is not None:
                k = (sw - p0) * d
                n, ok = (k, True) if 0 <= k <= lim else (lim, False)
            else:
                n, ok = (0, True) if self.ref_active(w, p0) else (lim, False)
        else:
            if sw is not None:
                n, ok = (1, True) if lim >= 1 else (0, False)  # released one step back
            else:
                n, ok = (0, True) if not self.ref_active(w, p0) else (lim, False)
        rate = w["rate"] if w["phase"] == 1 else w["rate2"]
        w["n"], w["ok"], w["d"], w["rt"] = n, ok, d, rate
        w["t_end"] = now + int(round(n * NS / rate))

    def wrun_pos(self, now):
        w = self.wrun
        k = min(w["n"], int((now - w["t0"]) * w["rt"] // NS))
        p = list(w["pos"])
        p[w["ax"]] = w["p0"] + w["d"] * k
        self.m.note(p)
        return p

    def wrun_step(self, now):
        w = self.wrun
        p = list(w["pos"])
        p[w["ax"]] = w["p0"] + w["d"] * w["n"]
        self.m.note(p)
        self.m.base = p
        if w["ok"] and w["phase"] == 1:
            w.update(phase=2, p0=p[w["ax"]], pos=p, t0=now)
            self.wrun_plan(now)
            return
        self.wrun = None
        self.pending = None
        self.m.last_stop = now
        if w["ok"]:
            self.offset[w["ax"]] = p[w["ax"]]            # counter := 0
            self.answer(now, 0)
        else:
            self.answer(now, 5)

    def rig_changed(self, now):
        """An input changed: a W watching an input may end now."""
        if self.wrun and self.switch[self.wrun["ax"]] is None:
            w = self.wrun
            p = self.wrun_pos(now)
            done = w["d"] * (p[w["ax"]] - w["p0"])
            w.update(p0=p[w["ax"]], pos=p, t0=now)
            self.wrun_plan(now)
            if not w["ok"]:
                w["n"] = max(0, w["n"] - done)
                w["t_end"] = now + int(round(w["n"] * NS / w["rt"]))
        self.check_interrupts(now)

    # -- interrupts (manual 12.5.11) [R35] -------------------------------------------
    def check_interrupts(self, now):
        if self.deaf_until is not None:
            return
        lvl = self.inputs[1] & 0x07
        act = (~(lvl ^ self.st[2])) & 0x07               # ST2 bit 0: active at 0
        hit = act & self.st[0] & 0x07
        if not hit:
            return
        self.st[4] |= hit
        if not self.st[6] & INTA:
            self.st[6] |= INTA
            self.m.halt(now)

    def motion_stopped(self, now):
        if self.pending == "H":
            self.pending = None
            self.answer(now, 0)


class Err(Exception):
    def __init__(self, code):
        self.code = code


def _ishex(s):
    return s != "" and all(ch in "0123456789ABCDEFabcdef" for ch in s)


def num1(s):
    """A decimal parameter with optional sign [R36]."""
    t = s[1:] if s[:1] in "+-" else s
    if not t or not t.isdigit() or not t.isascii():
        raise Err(4)
    if len(t) > 12:
        raise Err(5)
    return int(s)


def nums(s, lo, hi):
    p = s.split(",")
    if not lo <= len(p) <= hi:
        raise Err(4)
    return [num1(x) for x in p]


def hexn(s):
    if not _ishex(s) or len(s) > 4:
        raise Err(4)
    return rng(int(s, 16), 0, 0xFF)


def rng(x, lo, hi):
    if not lo <= x <= hi:
        raise Err(5)
    return x


def axis(ch):
    i = "XYZxyz".find(ch) if len(ch) == 1 else -1
    if i < 0:
        raise Err(5 if ch.isalpha() and len(ch) == 1 else 4)
    return i % 3


# ----------------------------------------------------------------------------
# Co-simulation: clock, line, rig (given/cosim.md, given/rig.md)
# ----------------------------------------------------------------------------
class CoSim:
    def __init__(self, model, address, baud):
        self.now = 0
        self.line_baud = baud
        self.b = round(10 * NS / baud)
        self.rxq = []            # (instant, byte) to the unit
        self.txq = []            # [instant, byte] to the host
        self.model = model
        self.unit = Unit(model, address, baud, self)
        self.out = []            # reply lines being built

    # the unit's transmitter
    def send(self, now, data):
        t = max(now, self.txq[-1][0] if self.txq else now)
        for byte in data:
            t += self.b
            self.txq.append([t, byte])

    def unit_next(self):
        return self.unit.next_event()

    def advance(self, limit, cr_stop):
        """Run the clock to `limit`; stop at a CR to the host if cr_stop."""
        rx = []
        guard = 0
        while True:
            cand = []
            tu = self.unit_next()
            if tu is not None:
                cand.append(tu)
            if self.txq:
                cand.append(self.txq[0][0])
            if self.rxq:
                cand.append(self.rxq[0][0])
            t = min(cand) if cand else None
            if t is None or t > limit:
                self.now = limit
                break
            self.now = max(self.now, t)
            if tu is not None and tu <= self.now:
                self.unit.process(self.now)
                if self.unit_next() == tu and tu <= self.now:
                    guard += 1
                    if guard > 1000:
                        raise RuntimeError("unit event does not progress at %d" % tu)
                continue
            if self.txq and self.txq[0][0] <= self.now:
                tt, byte = self.txq.pop(0)
                rx.append((tt, byte))
                if byte == 0x0D and cr_stop:
                    break
                continue
            tt, byte = self.rxq.pop(0)
            if self.line_baud == self.unit.baud:      # [R37]
                self.unit.receive(self.now, byte)
        i = 0
        while i < len(rx):                 # one rx line per run of back-to-back bytes
            j = i + 1
            while j < len(rx) and rx[j][0] == rx[j - 1][0] + self.b:
                j += 1
            self.out.append("rx %d %s" % (rx[i][0], "".join("%02X" % b for _, b in rx[i:j])))
            i = j
        return any(b == 0x0D for _, b in rx)

    # commands
    def cmd(self, line):
        w = line.split()
        if not w:
            return None
        self.out = []
        c = w[0]
        try:
            if c in ("quit", "exit"):
                sys.exit(0)
            if c == "tx":
                if len(w) not in (2, 3) or len(w[1]) % 2 or not _ishex(w[1]):
                    return "error: usage tx HEX [T]"
                data = bytes.fromhex(w[1])
                T = None
                if len(w) == 3:
                    T = number(w[2])
                    if T < self.now + len(data) * self.b:
                        return "error: T before the end of the bytes"
                self.do_tx(data, T)
                return "\n".join(self.out)
            if c == "batch":
                # extension "batch" and "batch-stops" (given/cosim.md, Extensions)
                if len(w) < 3 or len(w) % 2 == 0:
                    return "error: usage batch D HEX [D HEX ...]"
                pairs = []
                for i in range(1, len(w), 2):
                    if len(w[i + 1]) % 2 or not _ishex(w[i + 1]):
                        return "error: bad HEX in batch"
                    pairs.append((number(w[i]), bytes.fromhex(w[i + 1])))
                for d, data in pairs:
                    cr = self.do_tx(data, self.now + len(data) * self.b + d)
                    if not cr:
                        break
                return "\n".join(self.out)
            if c == "until":
                if len(w) != 2:
                    return "error: usage until T"
                T = number(w[1])
                if T < self.now:
                    return "error: until before now"
                self.advance(T, True)
                self.out.append("now %d" % self.now)
                return "\n".join(self.out)
            if c == "next":
                if len(w) != 1:
                    return "error: usage next"
                cand = [x for x in (self.unit_next(),
                                    self.txq[0][0] if self.txq else None,
                                    self.rxq[0][0] if self.rxq else None) if x is not None]
                cand = [max(x, self.now + 1) for x in cand]
                return "next %d" % min(cand) if cand else "next none"
            if c == "baud":
                if len(w) != 2:
                    return "error: usage baud N"
                n = number(w[1])
                if n == 0:
                    return "error: bad rate"
                self.set_baud(n)
                return "ok"
            w, at = self.strip_addr(w)
            c = w[0]
            if c == "state" and len(w) == 1:
                return json.dumps(self.state())
            if c == "in" and len(w) == 3:
                port = number(w[1])
                if port > 2 or len(w[2]) != 2 or not _ishex(w[2]):
                    return "error: usage in PORT XX"
                self.unit.inputs[port] = int(w[2], 16)
                self.unit.rig_changed(self.now)
                return "ok"
            if c == "switch" and len(w) == 3:
                ax = "XYZ".find(w[1].upper()) if len(w[1]) == 1 else -1
                if ax < 0:
                    return "error: no such axis on a GVE84"
                if w[2] == "none":
                    self.unit.switch[ax] = None
                else:
                    s = w[2]
                    t = s[1:] if s[:1] in "+-" else s
                    if not t.isdigit() or not t.isascii() or len(t) > 20:
                        return "error: bad position"
                    self.unit.switch[ax] = int(s)
                return "ok"
            if c == "power-on" and len(w) == 1:
                self.power_on()
                return "ok"
            if c == "rate":
                return "error: the GVE84's rate is fixed at order time"
            if c == "help":
                return ("commands: tx HEX [T] | until T | next | baud N | in PORT HEX | "
                        "switch AXIS POS|none | power-on | state | quit")
            return "error: unknown command %r" % line.strip()
        except ValueError as e:
            return "error: %s" % e

    def do_tx(self, data, T):
        """The host's bytes from now, back to back; then on to T unless a CR came."""
        end = self.now + len(data) * self.b
        for i, byte in enumerate(data):
            self.rxq.append((self.now + (i + 1) * self.b, byte))
        cr = self.advance(end, False)
        if T is not None and not cr:
            cr = self.advance(T, True)
        self.out.append("now %d" % self.now)
        return cr

    def strip_addr(self, w):
        if len(w) > 1 and w[-1].startswith("@"):
            a = w[-1][1:]
            if not a.isdigit() or int(a) != self.unit.address:
                raise ValueError("no unit at %s" % w[-1])
            return w[:-1], int(a)
        return w, None

    def set_baud(self, n):
        old = self.b
        self.b = round(10 * NS / n)
        self.line_baud = n
        # bytes to the host not yet begun take the new time
        prev = None
        for e in self.txq:
            begin = e[0] - old
            if begin >= self.now:
                start = max(self.now, prev if prev is not None else self.now)
                e[0] = start + self.b
            prev = e[0]

    def power_on(self):
        u = self.unit
        u.reset(self.now, restart=True)
        # an answer already on its way completes; nothing later is sent

    def state(self):
        u = self.unit
        now = self.now
        phys = u.physical(now)
        return {
            "profile": self.model,
            "position": u.counters(now),
            "physical": phys,
            "excursion": [list(x) for x in u.m.exc],
            "status": ["%02X" % (u.st6() if i == 6 else u.st[i]) for i in range(7)],
            "outputs": "%02X" % u.outputs,
            "spindle": 0,
            "rate_position": None,
            "rate": None,
            "inputs": {str(i): "%02X" % u.inputs[i] for i in range(3)},
            "addresses": [u.address],
            "time_ns": now,
            "queue": len(u.m.q),
            "index": u.index,
            "checksums": u.cs,
            "modal": {"V": u.v, "A": u.a // 1000, "B": u.b, "$": u.short,
                      "T": u.t_dwell, "VK": u.vk, "VL": list(u.vl), "XM": u.xm},
            "kept": u.kept is not None,
            "packet_open": u.packet is not None,
        }


def number(s):
    if not s.isdigit() or not s.isascii() or len(s) > 20:
        raise ValueError("bad number %r" % s)
    return int(s)


def main(argv):
    import argparse
    ap = argparse.ArgumentParser(description="GVE84 simulator")
    ap.add_argument("--cosim", action="store_true", help="co-simulation on stdin/stdout")
    ap.add_argument("--model", default="GVE84-100", choices=sorted(MODELS))
    ap.add_argument("--address", type=int, default=0, choices=range(8))
    ap.add_argument("--baud", type=int, default=115200, choices=(38400, 115200))
    a = ap.parse_args(argv)
    if not a.cosim:
        print("only --cosim is implemented (virtual time, given/cosim.md)", file=sys.stderr)
        return 2
    sim = CoSim(a.model, a.address, a.baud)
    out = sys.stdout
    out.write("cosim 1 batch batch-stops\n")
    out.flush()
    for line in sys.stdin:
        r = sim.cmd(line.rstrip("\n").rstrip("\r"))
        if r is not None:
            out.write(r + "\n")
            out.flush()
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
