#!/usr/bin/env python3
"""selftest.py - self-test of host.py against a tiny fake GVE54 on a pseudo-terminal.

The fake unit answers like the examples in the instruction set:
    !0L1000,0,0 -> 0      !1PF -> 0,-1000,2000,50     !0C100,20,0 -> 1 (queue full)
    !0V1000 -> 8 (INTA)   !0SW8,F1 -> 5               !1SR2 -> 0,2B
It is a model written from the same document, not the real firmware.
python3 selftest.py  ->  exit 0 when every check passes.
"""
import os
import re
import subprocess
import sys
import tempfile
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import host  # noqa: E402


class FakeUnit(threading.Thread):
    def __init__(self, address="0", qsize=96, faults=None, interrupt_after=None,
                 restart_after=None, move_rate=1.0, at_self=False, restart_on_idle_at=None):
        super().__init__(daemon=True)
        self.master, self.slave = os.openpty()
        import tty
        tty.setraw(self.slave)
        self.path = os.ttyname(self.slave)
        self.address = address
        self.qsize = qsize
        self.faults = faults or {}          # frame number -> 'drop' | 'garble' | 'late' | 'noise'
        self.interrupt_after = interrupt_after  # accepted vector count that triggers INTA
        self.restart_after = restart_after      # accepted vector count -> power loss mid-motion
        self.move_rate = move_rate              # simulated speed multiplier
        self.at_self = at_self                  # variant: @ counts itself
        self.restart_on_idle_at = restart_on_idle_at  # (n accepted, frame body): power loss while idle
        self.frames = []                     # every frame body received
        self.accepted = []                   # (kind, vec) accepted into the queue
        self.completed = []                  # vectors fully executed
        self.stop = False
        self.pending = []                    # (time, bytes) delayed answers
        self.silent_until = 0.0
        self.reset_state()

    def reset_state(self):
        self.pos = [0, 0, 0]
        self.queue = []          # [remaining vector (list), original]
        self.inta = False
        self.intcom = False
        self.index = 0
        self.st = [0] * 7
        self.speed = 1000
        self.last = time.monotonic()
        self.carry = 0.0

    # -- motion model: steps run at V*move_rate per second along the dominant axis
    def advance(self):
        now = time.monotonic()
        dt, self.last = now - self.last, now
        if self.inta:
            return
        budget = self.carry + dt * self.speed * self.move_rate
        while self.queue and budget >= 1:
            rem, orig = self.queue[0]
            m = max(abs(c) for c in rem)
            if m == 0:
                self.queue.pop(0)
                self.completed.append(orig)
                continue
            k = min(m, int(budget))
            step = [int(round(c * k / m)) for c in rem]
            for i in range(3):
                self.pos[i] += step[i]
                rem[i] -= step[i]
            budget -= k
            if max(abs(c) for c in rem) == 0:
                self.queue.pop(0)
                self.completed.append(orig)
        self.carry = budget if self.queue else 0.0

    def flags(self):
        f = 0
        if self.queue:
            f |= 0x40
        if self.inta:
            f |= 0x80
        if self.intcom:
            f |= 0x10
        if len(self.queue) >= self.qsize:
            f |= 0x20
        return f

    def code(self, err):
        return "%X" % (err | (8 if self.inta else 0))

    def handle(self, body):
        """Returns the answer text (without CR) for one frame body (after '!A')."""
        self.advance()
        if body == "@":
            if self.at_self:
                self.index = (self.index + 1) % 256
            return "0,%02X" % self.index
        self.index = (self.index + 1) % 256
        m = re.fullmatch(r"([LC])(-?\d+),(-?\d+),(-?\d+)", body)
        if m:
            vec = [int(m.group(i)) for i in (2, 3, 4)]
            if any(abs(c) > 65535 for c in vec):
                return self.code(5)
            if m.group(1) == "L" and self.queue:
                return self.code(1)
            if len(self.queue) >= self.qsize:
                return self.code(1)
            self.queue.append([list(vec), (m.group(1), tuple(vec))])
            self.accepted.append((m.group(1), tuple(vec)))
            if self.interrupt_after is not None and len(self.accepted) == self.interrupt_after:
                self.inta = True        # an interrupt input fires
            if self.restart_after is not None and len(self.accepted) == self.restart_after:
                self.restart_after = None
                self.power_loss_at = time.monotonic() + 0.05
            return self.code(0)
        if body == "F" or body == "SR6":
            return "%s,%02X" % (self.code(0), self.flags())
        if body == "PF":
            return "%s,%d,%d,%d" % (self.code(0), *self.pos)
        if body == "P":
            return "%s,%d,%d" % (self.code(0), self.pos[0], self.pos[1])
        m = re.fullmatch(r"SR([0-6])", body)
        if m:
            return "%s,%02X" % (self.code(0), self.st[int(m.group(1))])
        m = re.fullmatch(r"SW([0-9A-F]+),([0-9A-F]{1,2})", body)
        if m:
            n = int(m.group(1), 16)
            if n > 5:
                return self.code(5)
            self.st[n] = int(m.group(2), 16)
            return self.code(0)
        m = re.fullmatch(r"V(\d+)", body)
        if m:
            v = int(m.group(1))
            if not 40 <= v <= 50000:
                return self.code(5)
            self.speed = v
            return self.code(0)
        if re.fullmatch(r"(A\d+|T\d+|B\d+|\$\d+|M[UD248F]|XA|XU|XD|N)", body):
            return self.code(0)
        if body == "D":
            self.queue = []
            self.inta = self.intcom = False
            return "0"
        if body == "G":
            if not self.inta:
                return self.code(6)
            self.inta = self.intcom = False
            self.interrupt_after = None
            self.last = time.monotonic()
            return "0" if self.queue else "6"
        if body == "H":
            self.inta = self.intcom = True
            return self.code(0)
        if body == "?":
            return "0,Ip54v3 fake"
        return self.code(3)

    def run(self):
        buf = b""
        nframe = 0
        import select
        self.power_loss_at = None
        while not self.stop:
            now = time.monotonic()
            if self.power_loss_at and now >= self.power_loss_at:
                self.power_loss_at = None
                self.silent_until = now + 2.0      # "po pripojeni napajeni ... cca po 2s"
                self.reset_state()
            for t, data in list(self.pending):
                if now >= t:
                    os.write(self.master, data)
                    self.pending.remove((t, data))
            r, _, _ = select.select([self.master], [], [], 0.01)
            if not r:
                continue
            try:
                buf += os.read(self.master, 1024)
            except OSError:
                break
            while b"\r" in buf:
                line, buf = buf.split(b"\r", 1)
                if time.monotonic() < self.silent_until:
                    continue
                i = line.rfind(b"!")
                if i < 0 or len(line) < i + 2:
                    continue
                if line[i + 1:i + 2].decode() != self.address:
                    continue
                body = line[i + 2:].decode("ascii", "replace")
                r = self.restart_on_idle_at
                if r and len(self.accepted) >= r[0] and body == r[1] and not self.queue:
                    self.restart_on_idle_at = None          # power loss: this frame is lost
                    self.silent_until = time.monotonic() + 2.0
                    self.reset_state()
                    self.frames.append("<power loss>")
                    continue
                nframe += 1
                self.frames.append(body)
                ans = (self.handle(body) + "\r").encode()
                fault = self.faults.get(nframe) or self.faults.get(body)
                if isinstance(fault, list):
                    fault = fault.pop(0) if fault else None
                if fault == "drop":
                    continue
                if fault == "garble":
                    ans = b"\x7f#" + ans[1:]
                elif fault == "noise":
                    ans = b"\x00~\r" + ans
                elif fault == "late":
                    self.pending.append((time.monotonic() + 0.5, ans))
                    continue
                os.write(self.master, ans)

    def close(self):
        self.stop = True
        self.join(1)
        os.close(self.master)
        os.close(self.slave)


FAILS = []


def check(cond, what):
    print(("  ok   " if cond else "  FAIL ") + what)
    if not cond:
        FAILS.append(what)


def run_host(unit, job_text, *extra, timeout=60):
    with tempfile.NamedTemporaryFile("w", suffix=".job", delete=False) as fh:
        fh.write(job_text)
        job = fh.name
    unit.start()
    try:
        p = subprocess.run([sys.executable, os.path.join(HERE, "host.py"), unit.path, job,
                            "--timeout", "0.15", "--resume-delay", "0.1", *extra],
                           capture_output=True, text=True, timeout=timeout)
    finally:
        unit.close()
        os.unlink(job)
    return p


def plan_of(job_text, corner=10.0):
    with tempfile.NamedTemporaryFile("w", suffix=".job", delete=False) as fh:
        fh.write(job_text)
    try:
        return [(k, tuple(v)) for k, *rest in host.plan(host.parse_job(fh.name), corner)
                if k in "LC" for v in [rest[0]]]
    finally:
        os.unlink(fh.name)


def main():
    print("1. frames and answers against the document's examples")
    for addr, body, text in (("0", "L1000,1000,20", "!0L1000,1000,20"), ("0", "C1000,1000,20", "!0C1000,1000,20"),
                             ("0", "L1000,0,0", "!0L1000,0,0"), ("1", "PF", "!1PF"),
                             ("0", "C100,20,0", "!0C100,20,0"), ("0", "V1000", "!0V1000"),
                             ("0", "SW8,F1", "!0SW8,F1"), ("1", "SR2", "!1SR2"), ("0", "T5", "!0T5"),
                             ("0", "V10000", "!0V10000"), ("0", "A50", "!0A50")):
        check(host.frame(addr, body) == (text + "\r").encode(), "frame %s" % text)
    a = host.parse_answer(b"0", "code")
    check(a and a.err == 0 and not a.inta, "answer '0' = OK")
    a = host.parse_answer(b"0,-1000,2000,50", "pos3")
    check(a and a.params == "-1000,2000,50", "answer '0,-1000,2000,50' to PF")
    a = host.parse_answer(b"1", "code")
    check(a and a.err == 1, "answer '1' = vector not accepted")
    a = host.parse_answer(b"8", "code")
    check(a and a.err == 0 and a.inta, "answer '8' = OK but INTA=1")
    a = host.parse_answer(b"5", "byte")
    check(a and a.err == 5, "answer '5' = parameter out of range")
    a = host.parse_answer(b"0,2B", "byte")
    check(a and a.params == "2B", "answer '0,2B' to SR2")
    check(host.parse_answer(b"0,2B", "code") is None, "'0,2B' rejected where a bare code is expected")
    check(host.parse_answer(b"\x7f#", "code") is None, "garbage rejected")
    pieces = host.split_vector((200000, -70000, 3))
    check(sum(p[0] for p in pieces) == 200000 and sum(p[1] for p in pieces) == -70000 and
          sum(p[2] for p in pieces) == 3 and all(max(map(abs, p)) <= 65535 for p in pieces),
          "long vector split exactly into <=65535 pieces")

    job = "# doc example job\nspeed 10000\n1000,0,0\n100,20,0\n\n100,20,0  # collinear\n0,0,-300\n"
    print("2. short job, frames captured by the fake unit")
    u = FakeUnit(move_rate=5)
    p = run_host(u, job, "--corner-deg", "15", "--dwell", "5", "--accel", "50")
    check(p.returncode == 0, "host exit 0 (stderr: %s)" % p.stderr.strip()[-300:])
    for f in ("V10000", "T5", "A50", "L1000,0,0", "C100,20,0", "L0,0,-300", "MF", "F", "@", "PF"):
        check(f in u.frames, "unit received !0%s" % f)
    check(u.accepted == [("L", (1000, 0, 0)), ("C", (100, 20, 0)), ("C", (100, 20, 0)), ("L", (0, 0, -300))],
          "each vector accepted exactly once, in order: %s" % u.accepted)
    check(u.pos == [1200, 40, -300], "final position %s" % u.pos)

    print("3. address 1, long vector split, lost / garbled / late / noisy answers")
    job2 = "speed 20000\n70000,0,0\n10,10,0\n10,10,0\n-5,3,1\n"
    want = plan_of(job2)
    u = FakeUnit(address="1", move_rate=20,
                 faults={"L70000,0,0": ["drop"], "C35000,0,0": ["garble"], "L10,10,0": ["late"],
                         "C10,10,0": ["noise"], "L-5,3,1": ["drop"]})
    p = run_host(u, job2, "--address", "1")
    check(p.returncode == 0, "host exit 0 (stderr: %s)" % p.stderr.strip()[-300:])
    check([(k, v) for k, v in u.accepted] == want, "vectors exactly once despite faults: %s" % u.accepted)
    check(u.pos == [70015, 23, 1], "final position %s" % u.pos)
    check("PF" in u.frames, "PF sent to address 1")

    print("3b. same with a unit whose @ counts itself")
    u = FakeUnit(address="1", move_rate=20, at_self=True,
                 faults={"L70000,0,0": ["drop"], "C35000,0,0": ["garble"], "C10,10,0": ["noise"]})
    p = run_host(u, job2, "--address", "1")
    check(p.returncode == 0, "host exit 0 (stderr: %s)" % p.stderr.strip()[-300:])
    check([(k, v) for k, v in u.accepted] == want, "vectors exactly once: %s" % u.accepted)

    print("4. small queue: flow control without overflow")
    job3 = "speed 50000\n" + "10,0,0\n" * 40
    u = FakeUnit(qsize=4, move_rate=0.02)
    p = run_host(u, job3)
    check(p.returncode == 0, "host exit 0 (stderr: %s)" % p.stderr.strip()[-300:])
    check(len(u.accepted) == 40 and u.pos == [400, 0, 0], "40 vectors accepted once, position %s" % u.pos)

    print("5. interrupt input mid-job")
    job4 = "speed 2000\n" + "20,0,0\n" * 10
    u = FakeUnit(interrupt_after=4, move_rate=1)
    p = run_host(u, job4)
    check(p.returncode == 3 and "interrupt" in p.stderr, "default: give up with exit 3 (%d: %s)"
          % (p.returncode, p.stderr.strip()[-200:]))
    check(len(u.accepted) == len(set(range(len(u.accepted)))) and len(u.accepted) <= 10, "no vector sent twice")
    u = FakeUnit(interrupt_after=4, move_rate=1)
    p = run_host(u, job4, "--on-interrupt", "resume")
    check(p.returncode == 0, "--on-interrupt resume: G and finish (stderr: %s)" % p.stderr.strip()[-200:])
    check(len(u.accepted) == 10 and u.pos == [200, 0, 0], "10 vectors once, position %s" % u.pos)

    print("6. restart (power loss) while vectors are pending")
    job5 = "speed 100\n" + "50,0,0\n" * 6
    u = FakeUnit(restart_after=2, move_rate=1, qsize=3)
    p = run_host(u, job5, "--link-timeout", "5")
    check(p.returncode == 6 and "restart" in p.stderr, "gives up with exit 6 (%d: %s)"
          % (p.returncode, p.stderr.strip()[-300:]))
    check(len(u.accepted) < 6, "stopped feeding after the restart (%d accepted)" % len(u.accepted))

    print("6b. restart while idle (nothing pending): set-up repeated, job completes")
    job6 = "speed 2000\n40,0,0\n0,40,0\n-40,0,0\n"
    u = FakeUnit(restart_on_idle_at=(1, "@"), move_rate=1)
    p = run_host(u, job6, "--link-timeout", "5")
    check(p.returncode == 0 and "restarted while idle" in p.stderr,
          "exit 0 with a warning (%d: %s)" % (p.returncode, p.stderr.strip()[-300:]))
    check("<power loss>" in u.frames and u.frames.count("MF") == 2, "set-up sent again after the restart")
    check(u.accepted == [("L", (40, 0, 0)), ("L", (0, 40, 0)), ("L", (-40, 0, 0))], "each vector once: %s" % u.accepted)

    print("7. bad job file")
    u = FakeUnit()
    p = run_host(u, "1,2\n")
    check(p.returncode == 2 and not u.frames, "exit 2, nothing sent")

    print("FAILED: %d" % len(FAILS) if FAILS else "ALL PASSED")
    return 1 if FAILS else 0


if __name__ == "__main__":
    sys.exit(main())
