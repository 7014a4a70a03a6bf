#!/usr/bin/env python3
"""selftest.py - self-test of host.py against a tiny fake GVE84 on a pseudo-terminal.

1. framing/checksums reproduce the manual's example frames byte for byte (12.3.2, 12.3.3);
2. the fake unit answers the manual's worked examples (so the fake speaks the manual's dialect);
3. host.py runs short jobs against the fake: plain, checksums, packets, and with injected
   faults (lost / damaged / late / noisy answers, damaged commands, full queue, input
   interrupt, restart, silent line).  Exit status 0 = all passed.
"""

import os
import select
import subprocess
import sys
import tempfile
import threading
import time
import tty

HERE = os.path.dirname(os.path.abspath(__file__))
sys.dont_write_bytecode = True
sys.path.insert(0, HERE)
import host  # noqa: E402


def cs(text):
    return "%02X" % (sum(text.encode()) & 0xFF)


# ---------------------------------------------------------------------------
# the fake unit (my reading of chapter 12; deliberately small)
# ---------------------------------------------------------------------------

class FakeUnit(threading.Thread):
    CAP = 64

    def __init__(self, fd, addr=0, rate=20000.0, start_pos=(0, 0, 0), faults=None,
                 idx_self=False, rej_idx=False, idx_radix=16, cs_on=False):
        super().__init__(daemon=True)
        self.fd, self.addr, self.rate = fd, addr, rate
        self.faults = dict(faults or {})       # key ('cmd', n) | ('C', n) | ('pkt', n) -> action
        self.idx_self, self.rej_idx, self.idx_radix = idx_self, rej_idx, idx_radix
        self.start_pos = list(start_pos)
        self.done = []          # vectors completed, in order
        self.accepted = []      # vectors accepted into the queue, in order
        self.log = []
        self.stop_flag = False
        self.silent_until = 0.0
        self.ncmd = 0
        self.nC = 0
        self.npkt = 0
        self.nF = 0
        self.accepted_at_restart = None
        self.restarts = 0
        self.reset(initial=True)
        self.cs = cs_on                         # e.g. left on by an earlier session

    def reset(self, initial=False):
        self.cs = False
        self.idx = 0
        self.queue = []
        self.cur = None            # [vec, start_pos, start_time, duration, frozen_progress]
        self.pos = list(self.start_pos) if initial else [0, 0, 0]
        self.inta = False
        self.intcom = False
        self.st = [0] * 7
        self.packet = None
        self.V, self.A, self.B, self.T = 1000, 20, 35000, 10

    # -- motion ---------------------------------------------------------------
    def _dur(self, v):
        return max(abs(c) for c in v) / self.rate + 0.001

    def update(self):
        now = time.monotonic()
        if self.inta:
            return
        while True:
            if self.cur is None:
                if not self.queue:
                    return
                v = self.queue.pop(0)
                self.cur = [v, list(self.pos), now, self._dur(v), 0.0]
                if ("start", len(self.done) + 1) in self.faults:
                    act = self.faults.pop(("start", len(self.done) + 1))
                    if act == "interrupt":
                        self.inta, self.st[4] = True, 0x01
                        return
            v, p0, t0, dur, _ = self.cur
            if now - t0 >= dur:
                self.pos = [a + b for a, b in zip(p0, v)]
                self.done.append(tuple(v))
                self.cur = None
                continue
            f = (now - t0) / dur
            self.pos = [a + int(round(f * b)) for a, b in zip(p0, v)]
            return

    def running(self):
        return self.cur is not None or bool(self.queue)

    def flags(self):
        f = 0
        if self.inta:
            f |= 0x80
        if self.running():
            f |= 0x40
        if len(self.queue) + (1 if self.cur else 0) >= self.CAP:
            f |= 0x20
        if self.intcom:
            f |= 0x10
        return f

    # -- I/O -------------------------------------------------------------------
    def send(self, text, action=None):
        if self.cs:
            text = text + "," + cs(text + ",")
        data = (text + "\r").encode()
        if action == "drop":
            return
        if action == "garble":
            b = bytearray(data)
            b[0] = ord("9") if b[0] != ord("9") else ord("1")
            data = bytes(b)
        if action == "noise":
            data = b"\xff\x00" + data
        if action == "noiseline":
            data = b"~#x!\r" + data
        if action == "late":
            time.sleep(0.8)
        self.log.append(("<<", data))
        try:
            os.write(self.fd, data)
        except OSError:
            pass

    def run(self):
        buf = b""
        while not self.stop_flag:
            try:
                r, _, _ = select.select([self.fd], [], [], 0.003)
            except (OSError, ValueError):
                return
            self.update()
            if not r:
                continue
            try:
                data = os.read(self.fd, 4096)
            except OSError:
                return
            if time.monotonic() < self.silent_until:
                continue                      # rebooting: deaf
            buf += data
            while b"\r" in buf:
                line, buf = buf.split(b"\r", 1)
                self.handle(line.decode("ascii", "replace"))

    # -- commands ----------------------------------------------------------------
    def code(self, err):
        return "%X" % (err | (8 if self.inta else 0))

    def handle(self, line):
        self.update()
        self.log.append((">>", line))
        if not line.startswith("!") or len(line) < 2 or line[1] != str(self.addr):
            return
        self.ncmd += 1
        body = line[2:]
        is_c = body.startswith("C") and self.packet is None
        in_pkt = self.packet is not None and not body.startswith("*")
        if is_c:
            self.nC += 1
        key_c = ("C", self.nC) if is_c else None
        action = self.faults.pop(("cmd", self.ncmd), None)
        if action is None and key_c:
            action = self.faults.pop(key_c, None)
        if body.startswith("F"):
            self.nF += 1
            if action is None:
                action = self.faults.pop(("F", self.nF), None)
        if action == "restart0":            # instantaneous reset, then the command is processed
            self.restarts += 1
            self.reset()
            self.accepted_at_restart = len(self.accepted)
            action = None
        if action is None and body.startswith("*E"):
            self.npkt += 1
            action = self.faults.pop(("pkt", self.npkt), None)
        if action == "restart":
            self.restarts += 1
            self.reset()
            self.silent_until = time.monotonic() + 2.0
            return
        if action == "lose":
            return                            # the command never arrived
        if self.cs:
            i = body.rfind(",")
            if i < 0 or cs(line[:len(line) - len(body) + i + 1]) != body[i + 1:].upper() or action == "badcs":
                if action == "badcs":
                    pass
                if not in_pkt:
                    if self.rej_idx:
                        self.idx = (self.idx + 1) & 0xFF
                    self.send(self.code(4))
                elif self.packet is not None:
                    self.packet.append(None)
                return
            body = body[:i]
        if in_pkt:
            self.packet.append(body)
            return
        ans, err = self.execute(body)
        if body not in ("@", ">") and (err == 0 or self.rej_idx):
            self.idx = (self.idx + 1) & 0xFF
        if body == "@" and self.idx_self:
            pass
        if action == "interrupt":
            self.inta, self.st[4] = True, 0x01
        self.send(ans, action)

    def ints(self, s):
        return [int(x) for x in s.split(",")]

    def execute(self, b):
        ok = self.code(0)
        if b == "%+":
            self.cs = True
            return ok, 0
        if b == "%-":
            self.cs = False
            return ok, 0
        if b == "?":
            return ok + ",IP84 v3 27.1.2010", 0
        if b == "Q":
            return ok + ",25020304", 0
        if b == "F":
            return ok + ",%02X" % self.flags(), 0
        if b == "PF":
            return ok + ",%d,%d,%d" % tuple(self.pos), 0
        if b == "P":
            return ok + ",%d,%d" % tuple(self.pos[:2]), 0
        if b == "@":
            if self.idx_self:
                self.idx = (self.idx + 1) & 0xFF
            return ok + "," + (("%02X" % self.idx) if self.idx_radix == 16 else str(self.idx)), 0
        if b.startswith("SR") and b[2:].isdigit():
            n = int(b[2:])
            if n > 6:
                return self.code(5), 5
            return ok + ",%02X" % (self.flags() if n == 6 else self.st[n]), 0
        if b.startswith("SW"):
            try:
                n, x = b[2:].split(",")
                n, x = int(n), int(x, 16)
            except ValueError:
                return self.code(4), 4
            if n > 6:
                return self.code(5), 5
            self.st[n] = x
            return ok, 0
        for letter, lo, hi, attr in (("V", 10, 100000, "V"), ("A", 1, 1000, "A"), ("T", 1, 24, "T"),
                                     ("$", 1, 2147483647, None), ("B", 10, 100000, "B")):
            if b.startswith(letter) and b[1:].lstrip("-").isdigit():
                n = int(b[1:])
                if not lo <= n <= hi:
                    return self.code(5), 5
                if attr:
                    setattr(self, attr, n)
                return ok, 0
        if b in ("VK", "VN", "XA", "XU", "XD"):
            return ok, 0
        if b[:1] in ("C", "L"):
            try:
                v = self.ints(b[1:])
                if len(v) != 3:
                    raise ValueError
            except ValueError:
                return self.code(4), 4
            if b[0] == "L" and self.running():
                return self.code(1), 1
            if len(self.queue) + (1 if self.cur else 0) >= self.CAP:
                return self.code(1), 1
            self.queue.append(tuple(v))
            self.accepted.append(tuple(v))
            self.update()
            return self.code(0), 0
        if b.startswith("*S"):
            self.packet = []
            return None, 0
        if b.startswith("*E"):
            pk, self.packet = self.packet or [], None
            try:
                n = int(b[2:])
            except ValueError:
                return self.code(4), 4
            vecs = []
            for c in pk:
                if c is None or not c.startswith("C"):
                    return self.code(4) + ",0", 4
                vecs.append(tuple(self.ints(c[1:])))
            if n != len(vecs):
                return self.code(2) + ",%d" % len(vecs), 2
            room = self.CAP - len(self.queue) - (1 if self.cur else 0)
            take = vecs[:max(0, room)]
            self.queue.extend(take)
            self.accepted.extend(take)
            self.update()
            return (self.code(0) if len(take) == n else self.code(1)) + ",%d" % len(take), 0
        if b == "H":
            if self.running():
                self.inta, self.intcom = True, True
            return ok if not self.running() else self.code(0), 0
        if b == "G":
            if not self.inta:
                return self.code(6), 6
            self.inta, self.intcom, self.st[4] = False, False, 0
            if self.cur:   # restart the frozen vector from where it stopped
                v, p0, t0, dur, _ = self.cur
                done = [a - c for a, c in zip(self.pos, p0)]
                rest = [a - c for a, c in zip(v, done)]
                self.cur = None
                self.queue.insert(0, ("__rest__", tuple(v), tuple(rest)))
            self._unpack_rest()
            return self.code(0), 0
        if b == "D":
            if self.running() and not self.inta:
                return self.code(7), 7
            self.queue, self.cur = [], None
            self.inta = self.intcom = False
            self.st[4] = self.st[5] = 0
            return self.code(0), 0
        if b == "N":
            if self.running():
                return self.code(7), 7
            self.pos = [0, 0, 0]
            return ok, 0
        if b == "J":
            self.reset()
            self.silent_until = time.monotonic() + 2.0
            return None, 0
        return self.code(3), 3

    def _unpack_rest(self):
        # the remainder of an interrupted vector: run it, then record the original vector once
        if self.queue and isinstance(self.queue[0], tuple) and self.queue[0] and self.queue[0][0] == "__rest__":
            _, orig, rest = self.queue.pop(0)
            now = time.monotonic()
            self.cur = [tuple(rest), list(self.pos), now, self._dur(rest), 0.0]
            self._orig = orig
            # when finished, update() appends `rest`; fix it up to the original vector
            self._fix_rest = True


class FakeUnitResumable(FakeUnit):
    def update(self):
        before = len(self.done)
        super().update()
        if getattr(self, "_fix_rest", False) and len(self.done) > before:
            self.done[before] = tuple(self._orig)
            self._fix_rest = False


# send() must not answer None (packet start)
_orig_send = FakeUnit.send


def _send(self, text, action=None):
    if text is None:
        return
    _orig_send(self, text, action)


FakeUnit.send = _send


# ---------------------------------------------------------------------------
# helpers
# ---------------------------------------------------------------------------

FAILS = []


def check(name, cond, detail=""):
    print("%-62s %s" % (name, "ok" if cond else "FAIL"))
    if not cond:
        if detail:
            print("    " + str(detail).replace("\n", "\n    "))
        FAILS.append(name)


def make_pty():
    m, s = os.openpty()
    tty.setraw(s)
    return m, s, os.ttyname(s)


def write_job(lines):
    f = tempfile.NamedTemporaryFile("w", suffix=".job", delete=False)
    f.write("\n".join(lines) + "\n")
    f.close()
    return f.name


def run_host(job, unit_kwargs=None, args=(), cls=FakeUnit, timeout=120, no_unit=False):
    m, s, path = make_pty()
    unit = None
    if not no_unit:
        unit = cls(m, **(unit_kwargs or {}))
        unit.start()
    t0 = time.monotonic()
    p = subprocess.run([sys.executable, os.path.join(HERE, "host.py"), path, job, "--timeout", "0.3",
                        "--poll", "0.005", "--max-wait", "10", *args],
                       capture_output=True, text=True, timeout=timeout)
    dt = time.monotonic() - t0
    if unit:
        unit.stop_flag = True
        unit.join(1)
    os.close(m)
    os.close(s)
    return p, unit, dt


def ask(fd, data, wait=0.3):
    os.write(fd, data)
    out = b""
    end = time.monotonic() + wait
    while time.monotonic() < end:
        r, _, _ = select.select([fd], [], [], 0.02)
        if r:
            out += os.read(fd, 4096)
            if out.endswith(b"\r"):
                break
    return out


# ---------------------------------------------------------------------------
# tests
# ---------------------------------------------------------------------------

MANUAL_PACKET = """!0*S,FA
!0C697,30,0,51
!0C692,92,0,54
!0C682,151,0,7F
!0C665,209,0,84
!0C645,268,0,87
!0C619,322,0,7F
!0C589,375,0,8D
!0C553,425,0,80
!0C515,471,0,7F
!0C471,515,0,7F
!0*E10,4D""".split("\n")


def test_frames():
    check("frame !0A100, checksum = 4F (12.3.2)", host.frame(0, "A100", True) == b"!0A100,4F\r")
    check("frame !0%-,CF (12.3.2)", host.frame(0, "%-", True) == b"!0%-,CF\r")
    check("frame !0%+ plain (12.3.2)", host.frame(0, "%+", False) == b"!0%+\r")
    check("frame !0L1000,1000,20 plain (12.5.2)", host.frame(0, "L1000,1000,20", False) == b"!0L1000,1000,20\r")
    mine = [host.frame(0, "*S", True)]
    for l in MANUAL_PACKET[1:-1]:
        body = l[2:].rsplit(",", 1)[0]
        mine.append(host.frame(0, body, True))
    mine.append(host.frame(0, "*E10", True))
    want = [(l + "\r").encode() for l in MANUAL_PACKET]
    check("packet example of 12.3.3 reproduced byte for byte", mine == want,
          "\n".join("%r vs %r" % (a, b) for a, b in zip(mine, want) if a != b))
    for raw, n in ((b"0,5C", 0), (b"0,10,E9", 1)):
        st, rep = host.parse_reply(raw, True, n)
        check("answer %s accepted with checksums" % raw.decode(), st == "ok" and rep.err == 0)
    st, rep = host.parse_reply(b"0,5D", True, 0)
    check("answer 0,5D rejected (bad checksum)", st == "badcs")
    for raw, n, code in ((b"0", 0, 0), (b"0,-1000,2000,50", 3, 0), (b"1", 0, 1), (b"8", 0, 8), (b"5", 0, 5),
                         (b"0,2B", 1, 0)):
        st, rep = host.parse_reply(raw, False, n)
        check("12.6 example answer %-16s parses (code %X)" % (raw.decode(), code), st == "ok" and rep.code == code)
    st, rep = host.parse_reply(b"8", False, 0)
    check("answer 8 = OK with INTA set", rep.err == 0 and rep.inta)


def test_fake_examples():
    m, s, path = make_pty()
    u = FakeUnit(m)
    u.start()
    fd = os.open(path, os.O_RDWR | os.O_NOCTTY)
    tty.setraw(fd)
    check("fake: !0L1000,0,0 -> 0", ask(fd, b"!0L1000,0,0\r") == b"0\r")
    time.sleep(0.1)
    check("fake: !0%+ -> 0,5C", ask(fd, b"!0%+\r") == b"0,5C\r")
    os.write(fd, "\r".join(MANUAL_PACKET[:-1]).encode() + b"\r")
    check("fake: manual packet -> 0,10,E9", ask(fd, (MANUAL_PACKET[-1] + "\r").encode(), 1.0) == b"0,10,E9\r")
    check("fake: !0%-,CF -> 0", ask(fd, b"!0%-,CF\r") == b"0\r")
    check("fake: !0SW8,F1 -> 5", ask(fd, b"!0SW8,F1\r") == b"5\r")
    u.stop_flag = True
    u.join(1)
    os.close(fd)
    os.close(m)
    os.close(s)


def vec_job(n, seed=1, size=60):
    import random
    rnd = random.Random(seed)
    vecs = []
    for _ in range(n):
        vecs.append((rnd.randint(-size, size), rnd.randint(-size, size), rnd.randint(-size // 4, size // 4)))
    return vecs


def job_lines(vecs, speed=None):
    out = ["# generated job"]
    if speed:
        out.append("speed %d" % speed)
    for i, v in enumerate(vecs):
        out.append("%d,%d,%d" % v)
        if i == len(vecs) // 2:
            out.append("")
            out.append("speed 2500   # change of speed mid-job")
    return out


def expect_ok(name, p, unit, vecs):
    check(name, p.returncode == 0 and unit.done == vecs and unit.accepted == vecs,
          "rc=%s done=%d/%d accepted=%d\n%s" % (p.returncode, len(unit.done), len(vecs), len(unit.accepted),
                                                p.stderr[-2000:]))


def test_jobs():
    vecs = [(100, 0, 0), (100, 50, 0), (0, 0, -20), (0, 0, 0), (-200, -50, 20)]
    job = write_job(["# short job", "speed 3000"] + ["%d, %d, %d" % v for v in vecs])
    p, u, _ = run_host(job)
    expect_ok("short job, plain frames", p, u, vecs)

    p, u, _ = run_host(job, args=["--checksums"], unit_kwargs={"start_pos": (5, -7, 11)})
    expect_ok("short job, checksums", p, u, vecs)

    long = vec_job(150)
    jl = write_job(job_lines(long, speed=4000))
    p, u, _ = run_host(jl, args=["--checksums", "--packets"], unit_kwargs={"rate": 6000.0})
    expect_ok("150 vectors, checksums + packets, queue overflows 64", p, u, long)

    p, u, _ = run_host(jl, args=[], unit_kwargs={"rate": 6000.0, "idx_radix": 10})
    expect_ok("150 vectors, plain, full queue, '@' decimal", p, u, long)


def test_faults():
    vecs = vec_job(40, seed=2)
    job = write_job(job_lines(vecs))
    faults = {("C", 3): "drop", ("C", 7): "garble", ("C", 10): "badcs", ("C", 14): "late",
              ("C", 18): "noise", ("C", 21): "lose", ("cmd", 60): "drop", ("cmd", 75): "garble",
              ("cmd", 90): "late", ("C", 30): "drop", ("C", 33): "noiseline", ("cmd", 47): "noiseline"}
    p, u, _ = run_host(job, args=["--checksums"], unit_kwargs={"faults": faults, "start_pos": (1, 2, 3)})
    expect_ok("faults (lost/damaged/late/noisy answers, damaged cmds), cs", p, u, vecs)
    check("  ... all injected faults were hit", not u.faults, u.faults)

    faults = {("C", 3): "drop", ("C", 8): "lose", ("C", 12): "garble", ("C", 20): "late",
              ("C", 25): "noiseline", ("C", 28): "noise"}
    p, u, _ = run_host(job, args=[], unit_kwargs={"faults": faults, "idx_self": True, "rej_idx": True})
    expect_ok("faults, plain, '@' counts itself and refusals (drain path)", p, u, vecs)

    long = vec_job(120, seed=3)
    jl = write_job(job_lines(long))
    faults = {("pkt", 2): "drop", ("pkt", 5): "lose", ("pkt", 7): "garble", ("pkt", 9): "badcs"}
    p, u, _ = run_host(jl, args=["--checksums", "--packets"], unit_kwargs={"faults": faults, "rate": 8000.0})
    expect_ok("packets with lost / damaged packet answers", p, u, long)


def test_stops():
    vecs = vec_job(30, seed=4)
    job = write_job(job_lines(vecs))
    p, u, _ = run_host(job, args=["--checksums"], unit_kwargs={"faults": {("start", 10): "interrupt"},
                                                                 "rate": 3000.0})
    check("input interrupt -> exit 4, message, no vector repeated",
          p.returncode == 4 and "interrupt" in p.stderr and u.done == vecs[:len(u.done)]
          and u.accepted == vecs[:len(u.accepted)], "rc=%s %s" % (p.returncode, p.stderr[-800:]))

    p, u, _ = run_host(job, args=["--checksums", "--on-interrupt", "resume", "--resume-delay", "0.05"],
                       unit_kwargs={"faults": {("start", 10): "interrupt"}, "rate": 3000.0},
                       cls=FakeUnitResumable)
    expect_ok("input interrupt with --on-interrupt resume (G)", p, u, vecs)

    p, u, _ = run_host(job, args=[], unit_kwargs={"faults": {("C", 12): "restart"}, "rate": 3000.0,
                                                  "start_pos": (1000, -500, 7)})
    check("unit restart mid-job (plain) -> exit 5, nothing sent twice",
          p.returncode == 5 and "restart" in p.stderr and u.accepted == vecs[:len(u.accepted)]
          and len(u.accepted) <= 12,
          "rc=%s %s" % (p.returncode, p.stderr[-800:]))

    p, u, _ = run_host(job, args=["--checksums"], unit_kwargs={"faults": {("C", 12): "restart"},
                                                                "rate": 3000.0})
    check("unit restart mid-job (checksums, start at 0,0,0) -> exit 5",
          p.returncode == 5 and "restart" in p.stderr, "rc=%s %s" % (p.returncode, p.stderr[-800:]))

    p, u, _ = run_host(job, args=[], unit_kwargs={"faults": {("F", 25): "restart0"}, "rate": 3000.0})
    check("instant unit restart, plain, start at 0,0,0 -> exit 5, no vector after it",
          p.returncode == 5 and "restart" in p.stderr and u.accepted_at_restart is not None
          and len(u.accepted) == u.accepted_at_restart and u.accepted == vecs[:len(u.accepted)],
          "rc=%s acc=%d at_restart=%s %s" % (p.returncode, len(u.accepted), u.accepted_at_restart,
                                             p.stderr[-800:]))

    p, u, dt = run_host(job, no_unit=True, args=["--retries", "2"])
    check("no unit on the line -> exit 1 within bounded time (%.1fs)" % dt,
          p.returncode == 1 and dt < 20, "rc=%s %s" % (p.returncode, p.stderr[-800:]))


def test_misc():
    vecs = [(30, 0, 0), (0, 30, 0), (-30, -30, 0)]
    job = write_job(["%d,%d,%d" % v for v in vecs])
    p, u, _ = run_host(job, args=["--address", "3", "--checksums"], unit_kwargs={"addr": 3})
    expect_ok("unit at address 3 (!3...)", p, u, vecs)

    p, u, _ = run_host(job, args=[], unit_kwargs={"cs_on": True})
    expect_ok("unit left with checksums ON, host plain (switches them off)", p, u, vecs)
    p, u, _ = run_host(job, args=["--checksums"], unit_kwargs={"cs_on": True})
    expect_ok("unit left with checksums ON, host --checksums", p, u, vecs)

    # SIGTERM while running: HALT, then DELETE, exit 130
    long = vec_job(60, seed=5, size=400)
    jl = write_job(job_lines(long))
    m, s, path = make_pty()
    u = FakeUnit(m, rate=2000.0)
    u.start()
    proc = subprocess.Popen([sys.executable, os.path.join(HERE, "host.py"), path, jl, "--timeout", "0.3"],
                            stderr=subprocess.PIPE, text=True)
    time.sleep(2.0)
    proc.terminate()
    try:
        _, err = proc.communicate(timeout=30)
    except subprocess.TimeoutExpired:
        proc.kill()
        _, err = proc.communicate()
    sent = [l for d, l in u.log if d == ">>"]
    u.stop_flag = True
    u.join(1)
    os.close(m)
    os.close(s)
    check("SIGTERM -> !0H then !0D, exit 130", proc.returncode == 130 and "!0H" in sent and "!0D" in sent
          and sent.index("!0D") > sent.index("!0H") and not u.running(),
          "rc=%s %s" % (proc.returncode, err[-500:]))


def main():
    test_frames()
    test_fake_examples()
    test_jobs()
    test_faults()
    test_stops()
    test_misc()
    print()
    if FAILS:
        print("FAILED: %d check(s): %s" % (len(FAILS), ", ".join(FAILS)))
        return 1
    print("all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
