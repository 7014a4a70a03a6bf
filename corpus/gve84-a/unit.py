"""One GVE84 unit: receiver/framing, checksums, packets, command interpreter,
status words, inputs/outputs, EEPROM, reset. Motion lives in motion.py.

The unit never reads a clock: every entry point receives the instant (integer
ns of virtual time) at which it happens.
"""
import os

from motion import Motion, Vec, NS
from protocol import (CR, INT_MAX, CmdError, checksum, with_checksum,
                      parse_dec, parse_hex, split_params)

MODELS = {"GVE84-15": 15000, "GVE84-50": 50000, "GVE84-100": 100000}

VERSION = "IP84 v3 27.1.2010"          # 12.2 (program) -- answer of '?'
CPU_ID = "25020304"                     # 12.5.1 example of Q (ddmmrrpp)
QUEUE_LEN = 64                          # 1 spec / 12.5.2
WATCHDOG_NS = 100_000_000               # READINGS: frame must complete in 100 ms
RESTART_NS = 2_000_000_000              # 12.4: "cca po 2s"
MAX_FRAME = 100                         # characters between '!' and CR
AXES = {"X": 0, "Y": 1, "Z": 2}


def _eeprom_factory():
    e = bytearray([0xFF] * 256)
    e[0x01] = 0x00        # 11: relay defaults to spindle
    e[0x05] = 0xFF        # 11.3: default FF
    return e


class Unit:
    def __init__(self, model="GVE84-100", address=0, eeprom_path=None, send=None):
        self.model = model
        self.fmax = MODELS[model]
        self.address = address
        self.send_cb = send            # send(t, bytes) -> instant the last byte completes
        self.eeprom_path = eeprom_path
        self.eeprom = _eeprom_factory()
        if eeprom_path and os.path.exists(eeprom_path):
            data = open(eeprom_path, "rb").read()
            if len(data) == 256:
                self.eeprom = bytearray(data)
        self._latch_eeprom()
        self.inputs = [0xFF, 0xFF, 0xFF]
        self.switches = {}             # axis index -> physical position (rig)
        self.motion = Motion(self)
        self._init_state(0)
        self.deaf_until = None         # the simulator starts with the unit ready
        self.brake_due = None
        if self.relay_fn == 0x08:  # long since powered: brake already released
            self.outputs &= ~0x02

    # ------------------------------------------------------------ reset 12.4
    def _init_state(self, t):
        self.st = [0] * 6              # ST0..ST5
        self.inta = False
        self.intcom = False
        self.st6_raw = 0               # bits 1..3 as written by SW6
        self.V = 1000
        self.A = 20                    # thousands of pulses/s^2
        self.B = self.fmax             # "B35000 ... pro 35000 hz verzi"
        self.short = 512
        self.T_ms = 1
        self.vk = False
        self.vl = [self.fmax] * 3
        self.xm = 100
        self.outputs = 0xFF
        self.checksums = False
        self.packet = None
        self.kept = None
        self.index = 0
        self.last_answer = None
        self.busy = None               # 'H' | 'W': an answer falls due later
        self.frame = None
        self.frame_deadline = None
        self.frame_addr = None
        self.reset_at = None
        self.irq_prev = 0

    def _reset(self, t):
        self.motion.stop_dead(t)
        for ax in range(3):
            self.motion.set_counter(t, ax, 0)
        self._init_state(t)
        self._latch_eeprom()
        self.deaf_until = t + RESTART_NS
        if self.relay_fn == 0x08:
            fd = min(self.eeprom[0xFD], 50)
            self.brake_due = self.deaf_until + fd * 100_000_000
        else:
            self.brake_due = None
        self.irq_prev = self._irq_signal()

    def _latch_eeprom(self):
        """Configuration bytes are read at start-up (READINGS)."""
        self.relay_fn = self.eeprom[0x01]
        self.stepdir = self.eeprom[0x05]

    def dir_sign(self, axis):
        return 1 if (self.stepdir >> axis) & 1 else -1

    def power_on(self, t):
        self._reset(t)

    # ------------------------------------------------------------ rig
    def set_input(self, t, port, value):
        self.inputs[port] = value & 0xFF
        if port == 1:
            self._irq_check(t)
            if self.motion.state == "ref":
                self.motion.ref_input_changed(t)

    def rig_switch(self, axis):
        return self.switches.get(axis)

    def ref_input_active(self, axis):
        bit = 1 << axis
        return ((self.inputs[1] ^ self.st[2]) & bit) == 0

    # ------------------------------------------------------------ interrupts
    def _irq_signal(self):
        active = (~(self.inputs[1] ^ self.st[2])) & 0x07
        return active & self.st[0] & 0x07

    def _irq_check(self, t):
        sig = self._irq_signal()
        new = sig & ~self.irq_prev
        self.irq_prev = sig
        if new:
            self.st[4] |= new
            self._set_inta(t)

    def _set_inta(self, t):
        self.inta = True
        if self.motion.state in ("run", "wait", "stopping"):
            self.motion.halt(t)

    def on_stopped(self, t):
        if self.busy == "H":
            self.busy = None
            self._answer(t, 0, None)

    def on_ref_done(self, t, ok):
        if self.busy == "W":
            self.busy = None
            self._answer(t, 0 if ok else 5, None)

    # ------------------------------------------------------------ status
    def st6(self):
        v = self.st6_raw & 0x0E
        if self.motion.stopping():
            v |= 0x01
        if self.intcom:
            v |= 0x10
        if self.motion.running_bit():
            v |= 0x40
        if self.inta:
            v |= 0x80
        return v

    def queue_full(self):
        if self.kept is not None:
            return len(self.motion.q) >= 1
        return len(self.motion.q) >= QUEUE_LEN

    def relay_on(self):
        fn = self.relay_fn
        bitmap = {0x00: 0, 0x01: 0, 0x08: 1, 0x02: 2, 0x03: 3}
        if fn == 0x09:
            return self.inta
        if fn in bitmap:
            return not (self.outputs >> bitmap[fn]) & 1
        return False

    # ------------------------------------------------------------ events
    def next_event(self):
        ts = [self.frame_deadline, self.motion.next_event(), self.reset_at,
              self.brake_due]
        if self.deaf_until is not None:
            ts.append(self.deaf_until)
        ts = [x for x in ts if x is not None]
        return min(ts) if ts else None

    def process(self, t):
        """Handle every own event due at or before t, in time order."""
        for _ in range(1000000):
            due = []
            if self.deaf_until is not None:
                due.append((self.deaf_until, 0))
            if self.frame_deadline is not None:
                due.append((self.frame_deadline, 1))
            if self.reset_at is not None:
                due.append((self.reset_at, 2))
            if self.brake_due is not None:
                due.append((self.brake_due, 3))
            me = self.motion.next_event()
            if me is not None:
                due.append((me, 4))
            due = [d for d in due if d[0] <= t]
            if not due:
                return
            at, kind = min(due)
            if kind == 0:
                self.deaf_until = None
            elif kind == 1:
                self._watchdog(at)
            elif kind == 2:
                self.reset_at = None
                self._reset(at)
            elif kind == 3:
                self.brake_due = None
                self.outputs &= ~0x02
            else:
                self.motion.on_event(at)
        raise RuntimeError("unit events did not settle")

    # ------------------------------------------------------------ receiver
    def receive(self, t, byte):
        if self.deaf_until is not None or self.reset_at is not None:
            return                     # restarting: the byte is lost
        if byte == ord("!"):
            self.frame = bytearray()
            self.frame_addr = None
            self.frame_deadline = t + WATCHDOG_NS
            return
        if self.frame is None:
            return
        if byte == CR:
            frame = bytes(self.frame)
            self.frame = None
            self.frame_deadline = None
            if self.frame_addr:
                self._frame(t, frame)
            return
        if byte == 0x0A:
            return
        if len(self.frame) == 0:
            self.frame_addr = (byte == ord("0") + self.address)
        if len(self.frame) <= MAX_FRAME:
            self.frame.append(byte)

    def _watchdog(self, t):
        addr = self.frame_addr
        self.frame = None
        self.frame_deadline = None
        if not addr or self.busy:
            return
        if self.packet is not None:
            if not self.packet["err"]:
                self.packet["err"] = 2
            return
        self._answer(t, 2, None, record=False)

    # ------------------------------------------------------------ answers
    def _answer(self, t, code, params, record=True):
        text = "%X" % ((8 if self.inta else 0) | (code & 7))
        if params:
            text += "," + ",".join(str(p) for p in params)
        if self.checksums:
            text = with_checksum(text)
        data = (text + "\r").encode("latin-1")
        if record:
            self.last_answer = data
        return self.send_cb(t, data)

    def _frame(self, t, frame):
        if self.busy:
            return                     # simplex: a frame during H/W is lost
        try:
            text = frame.decode("latin-1")
        except Exception:
            text = ""
        body = text[1:]
        # checksum (12.3.2)
        if self.checksums:
            k = body.rfind(",")
            ok = False
            if k >= 0:
                field = body[k + 1:]
                if 1 <= len(field) <= 2 and all(c in "0123456789ABCDEFabcdef" for c in field):
                    ok = int(field, 16) == checksum("!" + text[0] + body[:k + 1])
            if not ok:
                if self.packet is not None:
                    p = self.packet
                    if not p["err"]:
                        p["err"] = 4
                    if body.startswith("*E"):
                        # the end of the packet must still be answered
                        self.packet = None
                        self._answer(t, p["err"], [p["count"]])
                    return
                self._answer(t, 4, None)
                return
            body = body[:k]
        elif body[:1] == "%" and "," in body:
            k = body.rfind(",")
            field = body[k + 1:]
            try:
                good = int(field, 16) == checksum("!" + text[0] + body[:k + 1])
            except ValueError:
                good = False
            if not good:
                self._answer(t, 4, None)
                return
            body = body[:k]
        # packets (12.3.3)
        if body[:1] == "*":
            self._packet_cmd(t, body)
            return
        if self.packet is not None:
            p = self.packet
            if p["err"]:
                return
            if body[:1] not in ("C", "B"):
                p["err"] = 3
                return
            try:
                self._execute(t, body)
                p["count"] += 1
                self.index = (self.index + 1) & 0xFF
            except CmdError as e:
                p["err"] = e.code
            return
        if body == ">":
            if self.last_answer is None:
                self._answer(t, 0, None)
            else:
                self.send_cb(t, self.last_answer)
            return
        try:
            res = self._execute(t, body)
        except CmdError as e:
            self._answer(t, e.code, None)
            return
        if body != "@":
            self.index = (self.index + 1) & 0xFF
        if res is None:
            return                     # answer falls due later (H, W)
        params, after = res if isinstance(res, tuple) and len(res) == 2 and callable(res[1]) else (res, None)
        end = self._answer(t, 0, params)
        if after:
            after(end)

    def _packet_cmd(self, t, body):
        if body == "*S":
            self.packet = {"count": 0, "err": 0}
            return
        if body.startswith("*E"):
            p = self.packet
            if p is None:
                self._answer(t, 4, None)
                return
            self.packet = None
            code = p["err"]
            arg = body[2:]
            if arg:
                try:
                    n = parse_dec(arg, 0, INT_MAX)
                except CmdError as e:
                    n = None
                    code = code or e.code
                if n is not None and n != p["count"] and not code:
                    code = 2
            self._answer(t, code, [p["count"]])
            return
        self._answer(t, 3, None)

    # ------------------------------------------------------------ commands
    def _execute(self, t, b):
        """Run the command body b (no '!', address, checksum). Returns the
        answer's parameter list ([] for none), None when the answer is
        deferred, or (params, after) with after(t_end) run once the answer
        has left. Raises CmdError for error answers."""
        if not b:
            raise CmdError(3)
        c = b[0]
        rest = b[1:]
        m = self.motion
        if c == "?":
            self._exact(rest)
            return [VERSION]
        if c == "Q":
            self._exact(rest)
            return [CPU_ID]
        if c in "LC":
            parts = rest.split(",") if rest else []
            if len(parts) not in (2, 3):      # 12.3.2 shows !0L1000,100
                raise CmdError(4)
            vals = [parse_dec(p) for p in parts] + [0]
            return self._vector(t, c, tuple(vals[:3]))
        if c == "T":
            self.T_ms = parse_dec(rest, 1, 24)
            return []
        if c == "$":
            self.short = parse_dec(rest, 1, INT_MAX)
            return []
        if c == "A":
            self.A = parse_dec(rest, 1, 1000)
            return []
        if c == "B":
            self.B = parse_dec(rest, 10, self.fmax)
            return []
        if c == "V":
            if rest == "K":
                self.vk = True
                return []
            if rest == "N":
                self.vk = False
                return []
            if rest.startswith("L"):
                parts = rest[1:].split(",")
                if len(parts) not in (3, 4):
                    raise CmdError(4)
                vals = [parse_dec(p, -INT_MAX, INT_MAX) for p in parts]
                for v in vals:
                    if v < 10 or v > self.fmax:
                        raise CmdError(5)
                self.vl = vals[:3]
                m.replan(t)
                return []
            if rest[:1].isalpha():
                raise CmdError(3)
            self.V = parse_dec(rest, 10, self.fmax)
            return []
        if c == "X":
            return self._exchange(t, rest)
        if c == "P":
            pos = m.counters(t)
            if rest == "":
                return [pos[0], pos[1]]
            if rest == "F":
                return pos
            raise CmdError(3)
        if c == "N":
            if rest == "":
                if self.st6() & 0x40:
                    raise CmdError(7)
                for ax in range(3):
                    m.set_counter(t, ax, 0)
                return []
            ax = AXES.get(rest[0].upper())
            if ax is None:
                raise CmdError(3 if rest[0].isalpha() else 4)
            val = parse_dec(rest[1:])
            if self.st6() & 0x40:
                raise CmdError(7)
            m.set_counter(t, ax, val)
            return []
        if c == "W":
            return self._reference(t, rest)
        if c == "K":
            self._exact(rest)
            if m.moving():
                raise CmdError(7)
            if self.kept is not None:
                raise CmdError(4)
            self.kept = (m.take_queue(t), self.st[4], self.st[5],
                         self.inta, self.intcom, self.st6_raw)
            self.st[4] = self.st[5] = 0
            self.inta = self.intcom = False
            self.st6_raw = 0
            return []
        if c == "R":
            self._exact(rest)
            if m.moving() or m.q:
                raise CmdError(7)
            if self.kept is None:
                raise CmdError(4)
            q, self.st[4], self.st[5], self.inta, self.intcom, self.st6_raw = self.kept
            self.kept = None
            m.give_queue(t, q)
            m.kick(t)
            return []
        if c == "H":
            self._exact(rest)
            self.inta = True
            self.intcom = True
            if m.state in ("run", "stopping"):
                m.halt(t)
                self.busy = "H"
                return None
            if m.state == "wait":
                m.halt(t)
            return []
        if c == "D":
            self._exact(rest)
            if m.moving():
                raise CmdError(7)
            m.delete_all(t)
            self.st[4] = self.st[5] = 0
            self.inta = self.intcom = False
            self.st6_raw = 0
            return []
        if c == "G":
            self._exact(rest)
            if not self.inta:
                raise CmdError(6)
            if m.stopping():
                raise CmdError(7)       # the stop ramp has not ended yet
            self.inta = False
            self.intcom = False
            self.st[4] = self.st[5] = 0
            if not m.q:
                raise CmdError(6)
            m.resume(t)
            return []
        if c == "E":
            if rest.startswith("R"):
                a = parse_hex(rest[1:])
                return ["%02X" % self.eeprom[a]]
            if rest.startswith("W"):
                a, v = split_params(rest[1:], 2)
                a = parse_hex(a)
                v = parse_hex(v)
                self.eeprom[a] = v
                self._save_eeprom()
                return []
            raise CmdError(3)
        if c == "O":
            port, v = split_params(rest, 2)
            port = parse_dec(port, 0, 9)
            v = parse_hex(v)
            if port != 0:
                raise CmdError(5)
            self.outputs = v
            return []
        if c == "I":
            port = parse_dec(rest, 0, 9)
            if port != 1:
                raise CmdError(5)
            return ["%02X" % self.inputs[1]]
        if c == "S":
            return self._status(t, rest)
        if c == "F":
            self._exact(rest)
            v = self.st6() | (0x20 if self.queue_full() else 0)
            return ["%02X" % v]
        if c == "@":
            self._exact(rest)
            return ["%02X" % self.index]
        if c == "J":
            self._exact(rest)

            def after(t_end):
                self.reset_at = t_end if t_end is not None else t
            return ([], after)
        if c == "%":
            if rest == "+":
                self.checksums = True
                return []
            if rest == "-":
                self.checksums = False
                return []
            raise CmdError(4)
        raise CmdError(3)

    @staticmethod
    def _exact(rest):
        if rest != "":
            raise CmdError(4)

    def _vector(self, t, kind, d):
        m = self.motion
        if kind == "C" and self.kept is not None:
            raise CmdError(1)
        if kind == "L":
            if m.q or m.moving():
                raise CmdError(1)
        elif self.queue_full():
            raise CmdError(1)
        speed = self.V * self.xm / 100.0
        vec = Vec(kind, d, speed, self.A * 1000.0, self.B, self.short, self.vk)
        m.push(t, vec)
        return []

    def _exchange(self, t, rest):
        m = self.motion
        if rest == "A":
            for v in m.q:
                v.speed = self.V * self.xm / 100.0
        elif rest == "U":
            for v in m.q:
                v.speed = min(v.speed * 17 / 16, float(self.fmax))
        elif rest == "D":
            for v in m.q:
                v.speed = max(v.speed * 15 / 16, 10.0)
        elif rest.startswith("M"):
            self.xm = parse_dec(rest[1:], 1, 1000)
            for v in m.q:
                v.speed = self.V * self.xm / 100.0
        else:
            raise CmdError(3)
        m.replan(t)
        return []

    def _reference(self, t, rest):
        if not rest:
            raise CmdError(4)
        ax = AXES.get(rest[0].upper())
        if ax is None:
            raise CmdError(5 if rest[0].isalpha() else 4)
        r = rest[1:]
        if r.startswith(","):
            r = r[1:]
        n2, n3, n4, n5 = split_params(r, 4)
        n2 = parse_dec(n2)
        n3 = parse_dec(n3, 10, self.fmax)
        n4 = parse_dec(n4, 0, INT_MAX)
        n5 = parse_dec(n5, 10, self.fmax)
        if n2 == 0:
            raise CmdError(5)
        if self.motion.moving() or self.motion.q:
            raise CmdError(7)
        self.motion.start_ref(t, ax, n2, n3, n4, n5)
        self.busy = "W"
        return None

    def _status(self, t, rest):
        if rest.startswith("R"):
            n = parse_dec(rest[1:], 0, 2147483647)
            if n > 6:
                raise CmdError(5)
            v = self.st6() if n == 6 else self.st[n]
            return ["%02X" % v]
        if rest.startswith("W"):
            n, x = split_params(rest[1:], 2)
            n = parse_dec(n, 0, 2147483647)
            if n > 6:
                raise CmdError(5)
            x = parse_hex(x)
            if n == 6:
                self.st6_raw = x & 0x0E
                self.intcom = bool(x & 0x10)
                was = self.inta
                self.inta = bool(x & 0x80)
                if self.inta and not was:
                    self._set_inta(t)
                elif was and not self.inta:
                    self.motion.kick(t)
                return []
            self.st[n] = x
            if n in (0, 2):
                self._irq_check(t)
            return []
        raise CmdError(3)

    def _save_eeprom(self):
        if self.eeprom_path:
            with open(self.eeprom_path, "wb") as f:
                f.write(bytes(self.eeprom))

    # ------------------------------------------------------------ rig view
    def state(self, t):
        m = self.motion
        m.track(t)
        st = ["%02X" % v for v in self.st] + ["%02X" % self.st6()]
        return {
            "profile": self.model,
            "addresses": [self.address],
            "time_ns": t,
            "position": m.counters(t),
            "physical": m.physical(t),
            "excursion": [list(e) for e in m.excursion],
            "status": st,
            "outputs": "%02X" % self.outputs,
            "relay": self.relay_on(),
            "relay_function": "%02X" % self.relay_fn,
            "stepdir": "%02X" % self.stepdir,
            "spindle": 0,
            "rate_position": None,
            "rate": None,
            "inputs": {str(i): "%02X" % self.inputs[i] for i in range(3)},
            "queue": len(m.q),
            "motion": m.state,
            "index": self.index,
            "checksums": self.checksums,
            "modal": {"V": self.V, "A": self.A, "B": self.B, "$": self.short,
                      "T": self.T_ms, "VK": self.vk, "VL": list(self.vl),
                      "XM": self.xm},
            "kept": self.kept is not None,
            "packet_open": self.packet is not None,
            "restarting": self.deaf_until is not None or self.reset_at is not None,
            "eeprom": self.eeprom_path,
        }
