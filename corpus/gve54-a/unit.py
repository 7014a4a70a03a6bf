"""The GVE54 unit (firmware Ip54v3): serial framing, command set, status words,
interrupt inputs, EEPROM, outputs.  Motion lives in motion.py.

The unit is driven by the event engine of sim.py through:
  on_rx(t, byte)        a byte from the host is complete at the receiver
  next_timer()          earliest own timer (watchdog, end of a restart)
  on_timer(t)           run the timers due at t
  on_motion(kind, t)    the motion reported an event
and it hands answers to the transmitter with self.send(bytes, t).
Numbered comments [Rn] refer to READINGS.md.
"""

import re

from motion import Motion, Vector, QUEUE_CAPACITY

CR = 0x0D
WATCHDOG_NS = 100_000_000          # [R6] a frame must be complete 100 ms after its '!'
RESTART_NS = 2_000_000_000         # "cca po 2s"
MAX_FRAME = 64                     # [R9]
VERSION = "IP54 v3 21.12.2007"     # [R27]
PROC_ID = "21120701"               # [R28]

# ST6 bits
STOP, FREE, INTCOM, RUN, INTA = 0x01, 0x02, 0x10, 0x40, 0x80
FULL = 0x20                        # F only

MODES = {"2": 8, "4": 4, "8": 2, "F": 1}    # micro-step mode -> P (counter units/pulse)

RE_DEC = re.compile(r"^-?[0-9]+$")
RE_HEX = re.compile(r"^[0-9A-Fa-f]+$")

TWO_CHAR = ("PF", "XA", "XU", "XD", "ER", "EW", "SR", "SW")
ONE_CHAR = "LCTVB$AKRHDGPNMOIF@>J?Q"


class CmdError(Exception):
    def __init__(self, code):
        super().__init__(code)
        self.code = code


def dec(s, lo, hi):
    if not RE_DEC.match(s):
        raise CmdError(4)
    if len(s.lstrip("-")) > 10:
        raise CmdError(5)
    v = int(s)
    if v < lo or v > hi:
        raise CmdError(5)
    return v


def hexb(s, hi=0xFF):
    if not RE_HEX.match(s):
        raise CmdError(4)
    if len(s) > 8:
        raise CmdError(5)
    v = int(s, 16)
    if v > hi:
        raise CmdError(5)
    return v


def split(params, count):
    parts = params.split(",")
    if len(parts) != count or any(p == "" for p in parts):
        raise CmdError(4)
    return parts


def none(params):
    if params != "":
        raise CmdError(4)


class Unit:
    def __init__(self, send, address="0"):
        self.send_bytes = send          # send(bytes, t): hand bytes to the transmitter
        self.address = address
        self.eeprom = bytearray(b"\xff" * 256)     # [R25]
        self.inputs = [0xFF, 0xFF, 0xFF]           # rig levels (pull-ups)
        self.switches = {}
        self.rate_position = None
        self.rate = None                           # the rate read at the last power-on
        self.motion = Motion()
        self.deaf_until = None
        self.frame = None
        self.pending_halt = False
        self._reset_state()

    # ------------------------------------------------------------ reset
    def _reset_state(self):
        """The reset state (after power-on or J), document section RESET."""
        self.st = [0] * 6                 # ST0..ST5
        self.inta = False
        self.intcom = False
        self.current_full = False         # MD: half current
        self.P = 1                        # MF: 1/16 steps
        self.A = 20                       # A20 (thousands of pulses/s^2)
        self.V = 1000
        self.S = 512                      # $512
        self.B = 50000
        self.T = 0                        # [R13] not in the reset list: 0 = no dwell
        self.outputs = 0xFF               # O0,FF
        self.index = 0
        self.last_answer = None
        self.kept = None                  # KEEP store (1 level)
        self.motion.hard_stop()
        self.motion.pos = [0, 0, 0]       # N
        self.frame = None
        self.pending_halt = False

    def restart(self, t):
        """Power-on or J: reset state now, deaf for 2 s.  The axes stay."""
        self._reset_state()
        self.deaf_until = t + RESTART_NS

    # ------------------------------------------------------------ status
    def st6(self):
        m = self.motion
        v = 0
        if m.stopping:
            v |= STOP
        if self.intcom:
            v |= INTCOM
        if m.queue or m.busy():
            v |= RUN
        if self.inta:
            v |= INTA
        return v

    def status_list(self):
        return ["%02X" % s for s in self.st] + ["%02X" % self.st6()]

    def running(self):
        """'za chodu' [R18]"""
        return self.motion.busy()

    # ------------------------------------------------------------ interrupts
    def check_interrupts(self, t):
        """Level-sensitive interrupt inputs [R20]: I1 = INTR0-7, I2 = INTR8-15."""
        lo = ~(self.inputs[1] ^ self.st[2]) & 0xFF & self.st[0]
        hi = ~(self.inputs[2] ^ self.st[3]) & 0xFF & self.st[1]
        if lo or hi:
            self.st[4] |= lo
            self.st[5] |= hi
            self._stop(t)

    def _stop(self, t):
        """Set INTA and brake the running motion along its ramp."""
        self.inta = True
        if self.motion.active:
            if self.motion.request_stop(t):
                self.on_motion("stopped", t)

    # ------------------------------------------------------------ rig
    def set_input(self, port, value, t):
        self.inputs[port] = value
        if not self.deaf_until:
            self.check_interrupts(t)

    # ------------------------------------------------------------ timers
    def next_timer(self):
        ts = []
        if self.frame is not None:
            ts.append(self.frame["deadline"])
        if self.deaf_until is not None:
            ts.append(self.deaf_until)
        return min(ts) if ts else None

    def on_timer(self, t):
        if self.deaf_until is not None and self.deaf_until <= t:
            self.deaf_until = None
            self.check_interrupts(t)
        f = self.frame
        if f is not None and f["deadline"] <= t:
            self.frame = None
            if f["addr"] == self.address:
                self._answer(2, None, t, remember=False)    # [R7]

    # ------------------------------------------------------------ motion events
    def on_motion(self, kind, t):
        if kind == "stopped":
            if self.pending_halt:
                self.pending_halt = False
                self._answer(0, None, t)
            if self.motion.queue and not self.inta:
                self.motion.start(t)             # only after SW6 cleared INTA mid-ramp
        elif kind == "dwell_end":
            if self.motion.queue and not self.inta:
                self.motion.start(t)

    # ------------------------------------------------------------ receiver
    def on_rx(self, t, byte):
        if self.deaf_until is not None:
            return                              # restarting: bytes lost
        if byte == 0x21:                        # '!' always begins a frame [R8]
            self.frame = {"addr": None, "buf": bytearray(), "deadline": t + WATCHDOG_NS,
                          "over": False}
            return
        f = self.frame
        if f is None:
            return                              # noise between frames [R8]
        if f["addr"] is None:
            if byte == CR:
                self.frame = None
                return
            f["addr"] = chr(byte)
            return
        if byte == CR:
            self.frame = None
            if f["addr"] == self.address:
                self._execute(f, t)
            return
        if len(f["buf"]) >= MAX_FRAME:
            f["over"] = True
        else:
            f["buf"].append(byte)

    # ------------------------------------------------------------ answers
    def _answer(self, code, params, t, remember=True):
        head = "%X" % ((8 if self.inta else 0) | code)
        text = head + ("," + ",".join(params) if params else "") + "\r"
        data = text.encode("latin-1")
        if remember:
            self.last_answer = data
        self.send_bytes(data, t)

    # ------------------------------------------------------------ commands
    def _execute(self, f, t):
        if f["over"]:
            code, params = 4, None
            name = None
        else:
            text = f["buf"].decode("latin-1")
            name, params = self._split_name(text)
            try:
                if name is None:
                    raise CmdError(3)
                handler = getattr(self, "cmd_" + self._attr(name))
                res = handler(params, t)
                code, params = 0, res
            except CmdError as e:
                code, params = e.code, None
        if name == ">" and code == 0:
            data = self.last_answer if self.last_answer is not None else b"0\r"   # [R23]
            self.send_bytes(data, t)
            return
        if code == 0 and name != "@":
            self.index = (self.index + 1) & 0xFF                                 # [R22]
        if name == "H" and code == 0 and self.pending_halt:
            return                                # answered once the axes stand
        if name == "J" and code == 0:
            self._answer(0, None, t)
            self.restart(t)                       # [R26]
            return
        self._answer(code, params, t)

    @staticmethod
    def _split_name(text):
        if text[:2] in TWO_CHAR:
            return text[:2], text[2:]
        if text[:1] and text[0] in ONE_CHAR:
            return text[0], text[1:]
        return None, ""

    @staticmethod
    def _attr(name):
        return {"$": "short", "@": "index", ">": "repeat", "?": "version"}.get(name, name)

    # -- vectors ---------------------------------------------------
    def _vector(self, params, cont):
        parts = split(params, 3)
        d = [dec(p, -65535, 65535) for p in parts]
        return Vector(d, self.P, self.V, self.A * 1000, self.B, self.S, cont, self.T)

    def cmd_L(self, params, t):
        vec = self._vector(params, False)
        m = self.motion
        if m.queue or m.busy():                 # the queue before it is not done [R10]
            raise CmdError(1)
        m.add(vec)
        self._maybe_start(t)

    def cmd_C(self, params, t):
        vec = self._vector(params, True)
        m = self.motion
        if m.full():
            raise CmdError(1)
        m.add(vec)
        self._maybe_start(t)

    def _maybe_start(self, t):
        m = self.motion
        if not self.inta and not m.busy() and m.queue:
            self.check_interrupts(t)
            if not self.inta:
                m.start(t)

    # -- modal values ----------------------------------------------
    def cmd_T(self, params, t):
        self.T = dec(params, 1, 24)

    def cmd_V(self, params, t):
        self.V = dec(params, 40, 50000)

    def cmd_B(self, params, t):
        self.B = dec(params, 40, 50000)

    def cmd_short(self, params, t):
        self.S = dec(params, 1, 65535)

    def cmd_A(self, params, t):
        self.A = dec(params, 1, 255)            # [R15]

    # -- queue control ---------------------------------------------
    def cmd_K(self, params, t):
        none(params)
        if self.running():
            raise CmdError(7)
        self.kept = (self.motion.snapshot_queue(), self.st[4], self.st[5],
                     self.inta, self.intcom)
        self.motion.queue = []
        self.motion.invalidate()
        self.st[4] = self.st[5] = 0
        self.inta = self.intcom = False
        self.check_interrupts(t)

    def cmd_R(self, params, t):
        none(params)
        if self.running():
            raise CmdError(7)
        q, s4, s5, inta, intcom = self.kept if self.kept else ([], 0, 0, False, False)
        self.motion.queue = [v.clone() for v in q]
        self.motion.invalidate()
        self.st[4], self.st[5], self.inta, self.intcom = s4, s5, inta, intcom
        self.check_interrupts(t)
        self._maybe_start(t)

    def cmd_H(self, params, t):
        none(params)
        self.intcom = True
        self.inta = True
        m = self.motion
        if m.active and not m.request_stop(t):
            self.pending_halt = True             # answered when the ramp ends

    def cmd_D(self, params, t):
        none(params)
        if self.running():
            raise CmdError(7)
        self.motion.queue = []
        self.motion.invalidate()
        self.st[4] = self.st[5] = 0
        self.inta = self.intcom = False
        self.check_interrupts(t)

    def _xchg(self, fn):
        self.motion.exchange(fn)

    def cmd_XA(self, params, t):
        none(params)
        V, A = self.V, self.A * 1000

        def f(vec):
            vec.V, vec.A = V, A
        self._xchg(f)

    def cmd_XU(self, params, t):
        none(params)

        def f(vec):
            vec.V = min(50000, vec.V + vec.V // 16)
            vec.A = vec.A + vec.A // 16
        self._xchg(f)

    def cmd_XD(self, params, t):
        none(params)

        def f(vec):
            vec.V = max(40, vec.V - vec.V // 16)
            vec.A = max(1000, vec.A - vec.A // 16)
        self._xchg(f)

    def cmd_G(self, params, t):
        none(params)
        if not self.inta:
            raise CmdError(6)                   # [R21]
        if self.motion.stopping:
            raise CmdError(7)
        self.inta = self.intcom = False
        self.st[4] = self.st[5] = 0
        if not self.motion.queue:
            self.check_interrupts(t)
            raise CmdError(6)
        self._maybe_start(t)

    # -- positions -------------------------------------------------
    def cmd_P(self, params, t):
        none(params)
        return [str(self.motion.pos[0]), str(self.motion.pos[1])]

    def cmd_PF(self, params, t):
        none(params)
        return [str(p) for p in self.motion.pos]

    def cmd_N(self, params, t):
        none(params)
        if self.st6() & RUN:                    # "pri RUN=1"
            raise CmdError(7)
        self.motion.pos = [0, 0, 0]

    # -- EEPROM ----------------------------------------------------
    def cmd_ER(self, params, t):
        n = hexb(split(params, 1)[0])
        return ["%02X" % self.eeprom[n]]

    def cmd_EW(self, params, t):
        a, x = split(params, 2)
        n, v = hexb(a), hexb(x)
        self.eeprom[n] = v

    # -- motor mode ------------------------------------------------
    def cmd_M(self, params, t):
        if len(params) != 1:
            raise CmdError(4)
        if params not in "UD248F":
            raise CmdError(5)
        if self.running():
            raise CmdError(7)
        if params == "U":
            self.current_full = True
        elif params == "D":
            self.current_full = False
        else:
            self.P = MODES[params]

    # -- I/O -------------------------------------------------------
    def cmd_O(self, params, t):
        port, x = split(params, 2)
        if dec(port, 0, 0) != 0:
            raise CmdError(5)
        self.outputs = hexb(x)

    def cmd_I(self, params, t):
        n = dec(split(params, 1)[0], 0, 2)
        return ["%02X" % self.inputs[n]]

    # -- status ----------------------------------------------------
    def cmd_SR(self, params, t):
        n = dec(split(params, 1)[0], 0, 6)
        return ["%02X" % (self.st6() if n == 6 else self.st[n])]

    def cmd_SW(self, params, t):
        a, x = split(params, 2)
        n, v = dec(a, 0, 6), hexb(x)
        if n < 6:
            self.st[n] = v
            if n < 4:
                self.check_interrupts(t)
            return None
        # ST6 [R19]: INTA, INTCOM and STOP are stored; RUN, FREE follow the unit
        self.intcom = bool(v & INTCOM)
        if v & (INTA | STOP):
            self._stop(t)
        else:
            self.inta = False
            self.check_interrupts(t)
            self._maybe_start(t)

    def cmd_F(self, params, t):
        none(params)
        return ["%02X" % (self.st6() | (FULL if self.motion.full() else 0))]

    def cmd_index(self, params, t):
        none(params)
        return ["%02X" % self.index]            # [R22]

    def cmd_repeat(self, params, t):
        none(params)

    def cmd_J(self, params, t):
        none(params)

    def cmd_version(self, params, t):
        none(params)
        return [VERSION]

    def cmd_Q(self, params, t):
        none(params)
        return [PROC_ID]

    # ------------------------------------------------------------ rig view
    def state(self):
        m = self.motion
        return {
            "profile": "GVE54",
            "addresses": [int(self.address, 16) if self.address in "0123456789ABCDEF" else self.address],
            "position": list(m.pos),
            "physical": list(m.phys),
            "excursion": [list(e) for e in m.exc],
            "status": self.status_list(),
            "outputs": "%02X" % self.outputs,
            "spindle": 0,
            "rate_position": self.rate_position,
            "rate": self.rate,
            "inputs": {str(i): "%02X" % v for i, v in enumerate(self.inputs)},
            "queue": len(m.queue),
            "index": self.index,
            "modal": {"V": self.V, "A": self.A, "B": self.B, "$": self.S, "T": self.T},
            "microstep": 16 // self.P,
            "current": "U" if self.current_full else "D",
            "kept": self.kept is not None,
            "packet_open": False,
            "restarting": self.deaf_until is not None,
        }
