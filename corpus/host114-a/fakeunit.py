"""A tiny fake GVE114 for the self-test, answering like the manual's examples.

It runs in a thread on the master side of a pseudo-terminal.  It is *our*
model of the unit (see READINGS.md), not the vendor's firmware.
"""

import os
import select
import threading
import time


def cs_of(text):
    return sum((text + ",").encode()) % 256


class FakeUnit:
    def __init__(self, master_fd, addr=0, capacity=2048, at_counts_itself=True,
                 errors_counted=True, fault=None, speed_scale=1.0, repeat_reexecutes=False):
        self.fd = master_fd
        self.addr = addr
        self.capacity = capacity
        self.at_counts_itself = at_counts_itself
        self.errors_counted = errors_counted
        self.fault = fault            # fault(kind, n_reply, text) -> None | "drop" | "corrupt" | ("delay", s) | "noise"
        self.speed_scale = speed_scale
        self.repeat_reexecutes = repeat_reexecutes   # the dangerous reading of '>'
        self.last_cmd = None
        self.lock = threading.RLock()
        self.executed = []            # (kind, x, y, z, a) in execution order
        self.received = []            # every decoded command text
        self.replies = 0
        self.stop = False
        self.silent_until = 0.0
        self.in1 = 0xFF
        self.stuck = False             # motor never finishes (for the timeout test)
        self.power_on()
        self.t_rx = threading.Thread(target=self._rx, daemon=True)
        self.t_mv = threading.Thread(target=self._motion, daemon=True)

    def power_on(self):
        with self.lock:
            self.cs = False
            self.pos = [0, 0, 0, 0]
            self.queue = []           # list of [kind, x, y, z, a, v]
            self.running = None       # [vector, t_end]
            self.inta = False
            self.intcom = False
            self.st = [0] * 7
            self.A, self.V, self.T, self.S, self.B = 20, 1000, 0, 512, 50000
            self.index = 0
            self.last_reply = b""
            self.packet = None
            self.buf = b""

    def start(self):
        self.t_rx.start()
        self.t_mv.start()
        return self

    # ------------------------------------------------------------ events
    def restart(self, silent=2.0):
        """Power loss: everything lost, unit deaf for `silent` seconds."""
        with self.lock:
            self.power_on()
            self.silent_until = time.monotonic() + silent

    def input_interrupt(self, bit=7):
        with self.lock:
            self.inta = True
            self.st[4] |= 1 << bit

    # ------------------------------------------------------------ motion
    def _motion(self):
        while not self.stop:
            time.sleep(0.001)
            with self.lock:
                now = time.monotonic()
                if self.running is not None and not self.stuck:
                    if now >= self.running[1]:
                        v = self.running[0]
                        for k in range(4):
                            self.pos[k] += v[k + 1]
                        self.executed.append(tuple(v[:5]))
                        self.running = None
                if self.running is None and self.queue and not self.inta:
                    v = self.queue.pop(0)
                    steps = max(abs(c) for c in v[1:5])
                    dur = steps / float(v[5]) * self.speed_scale
                    if v[0] == "L":
                        dur += self.T / 1000.0
                    self.running = [v, now + dur]

    def _run_bit(self):
        return self.running is not None or bool(self.queue)

    def flags(self):
        f = 0
        if self._run_bit():
            f |= 0x40
        if self.inta:
            f |= 0x80
        if self.intcom:
            f |= 0x10
        if len(self.queue) + (1 if self.running else 0) >= self.capacity:
            f |= 0x20
        return f

    # ------------------------------------------------------------ serial
    def _rx(self):
        while not self.stop:
            try:
                r, _, _ = select.select([self.fd], [], [], 0.05)
                if not r:
                    continue
                data = os.read(self.fd, 4096)
            except OSError:
                return
            if time.monotonic() < self.silent_until:
                continue
            self.buf += data
            while True:
                cut = [i for i in (self.buf.find(b"\r"), self.buf.find(b"\n")) if i >= 0]
                if not cut:
                    break
                i = min(cut)
                line, self.buf = self.buf[:i], self.buf[i + 1:]
                if line:
                    self._line(line.decode("latin-1"))

    def _send(self, text, cmd):
        with self.lock:
            payload = text
            if self.cs:
                payload = "%s,%02X" % (text, cs_of(text))
            data = (payload + "\r").encode()
            self.last_reply = data
            self.replies += 1
            n = self.replies
        act = self.fault("reply", n, cmd) if self.fault else None
        if act == "drop":
            return
        if act == "corrupt":
            b = bytearray(data)
            if self.cs:        # a damaged digit: only the checksum can tell
                b[0] = ord("7") if b[0] != ord("7") else ord("6")
            else:              # without checksums only visibly broken lines are detectable
                b[1:1] = b"#"
            data = bytes(b)
        if act == "noise":
            data = b"\x00#~" + data
        if isinstance(act, tuple) and act[0] == "delay":
            def later():
                time.sleep(act[1])
                os.write(self.fd, data)
            threading.Thread(target=later, daemon=True).start()
            return
        os.write(self.fd, data)

    def _line(self, line):
        if not line.startswith("!") or len(line) < 2 or not line[1].isdigit():
            return
        if int(line[1]) != self.addr and int(line[1]) != 7:
            return
        with self.lock:
            body = line
            if self.cs:
                pos = body.rfind(",")
                ok = pos > 0 and body[pos + 1:] and \
                    all(c in "0123456789ABCDEFabcdef" for c in body[pos + 1:]) and \
                    int(body[pos + 1:], 16) == cs_of(body[:pos])
                if not ok:
                    self._count(False)
                    code = 4
                    self._send(self._code(code), line)
                    return
                body = body[:pos]
            cmd = body[2:]
            self.received.append(cmd)
            if self.packet is not None and not cmd.startswith("*E"):
                self.packet.append(cmd)
                return
            if cmd == ">":
                if self.repeat_reexecutes and self.last_cmd:
                    cmd = self.last_cmd
                else:
                    data = self.last_reply
                    os.write(self.fd, data)
                    return
            self.last_cmd = cmd
            code, extra = self._exec(cmd)
            if cmd == "@":
                pass
            else:
                self._count(code == 0)
            text = self._code(code) + ("," + extra if extra is not None else "")
            self._send(text, cmd)

    def _count(self, ok):
        if ok or self.errors_counted:
            self.index = (self.index + 1) % 256

    def _code(self, err):
        return "%X" % (err | (8 if self.inta else 0))

    # ------------------------------------------------------------ commands
    def _vec(self, kind, params):
        p = [int(x) for x in params.split(",")]
        if len(p) not in (3, 4):
            return 4
        if len(p) == 3:
            p.append(0)
        if any(abs(c) > 2147483647 for c in p):
            return 5
        if kind == "L":
            if self._run_bit():
                return 1
        else:
            if len(self.queue) + (1 if self.running else 0) >= self.capacity:
                return 1
            # a C vector cannot join a queue that holds an L still waiting
        self.queue.append([kind] + p + [self.V])
        return 0

    def _exec(self, cmd):
        try:
            if cmd == "@":
                if self.at_counts_itself:
                    self.index = (self.index + 1) % 256
                return 0, "%d" % self.index
            if cmd == "?":
                return 0, "IP114/500 x16 16.9.2018 (c) Gravos (P.Borovsky)"
            if cmd == "Q":
                return 0, "25022504"
            if cmd == "%+":
                self.cs = True
                return 0, None
            if cmd == "%-":
                self.cs = False
                return 0, None
            if cmd == "F":
                return 0, "%02X" % self.flags()
            if cmd.startswith("SR"):
                n = int(cmd[2:])
                if n == 6:
                    return 0, "%02X" % (self.flags() & ~0x20)
                return 0, "%02X" % self.st[n]
            if cmd.startswith("SW"):
                n, x = cmd[2:].split(",")
                if not 0 <= int(n) <= 6:
                    return 5, None
                self.st[int(n)] = int(x, 16)
                return 0, None
            if cmd == "PF":
                return 0, "%d,%d,%d" % tuple(self.pos[:3])
            if cmd == "P":
                return 0, "%d,%d" % tuple(self.pos[:2])
            if cmd == "I1":
                return 0, "%02X" % self.in1
            if cmd == "I2":
                return 0, "FF"
            if cmd in ("VK", "VN", "XA", "XU", "XD"):
                return 0, None
            if cmd.startswith("XM"):
                int(cmd[2:])
                return 0, None
            if cmd.startswith("VL"):
                return 0, None
            if cmd[0] == "$" and cmd[1:].isdigit():
                n = int(cmd[1:])
                if not 1 <= n <= 2147483647:
                    return 5, None
                self.S = n
                return 0, None
            if cmd[0] in "AVTB" and cmd[1:].lstrip("-").isdigit():
                n = int(cmd[1:])
                lim = {"A": (1, 1000000), "V": (10, 100000), "T": (1, 24),
                       "B": (10, 100000)}[cmd[0]]
                if not lim[0] <= n <= lim[1]:
                    return 5, None
                setattr(self, cmd[0], n)
                return 0, None
            if cmd[0] in "LC":
                return self._vec(cmd[0], cmd[1:]), None
            if cmd == "*S":
                self.packet = []
                return 0, None
            if cmd.startswith("*E"):
                n = int(cmd[2:])
                pk, self.packet = self.packet or [], None
                if n != len(pk):
                    return 2, "%d" % len(pk)
                done = 0
                for c in pk:
                    if c[0] == "C":
                        e = self._vec("C", c[1:])
                    elif c[0] == "B":
                        e, _ = self._exec(c)
                    else:
                        e = 3
                    if e:
                        return e, "%d" % done
                    done += 1
                return 0, "%d" % done
            if cmd == "G":
                if not self.inta:
                    return 6, None
                self.inta = False
                self.intcom = False
                self.st[4] = self.st[5] = 0
                return 0, None
            if cmd == "D":
                if self.running is not None and not self.inta:
                    return 7, None
                self.queue = []
                self.running = None
                self.inta = False
                self.st[4] = self.st[5] = 0
                return 0, None
            if cmd == "H":
                self.inta = True
                self.intcom = True
                return 0, None
            if cmd == "N":
                self.pos = [0, 0, 0, 0]
                return 0, None
            if cmd == "J":
                self.power_on()
                return 0, None
            return 3, None
        except (ValueError, IndexError, KeyError):
            return 4, None
