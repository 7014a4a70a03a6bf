#!/usr/bin/env python3
"""Self-test: host.py against a fake GVE54 unit on a pseudo-terminal pair.
Prints PASS/FAIL per check; exit 0 when all pass."""
import io
import contextlib
import os
import pty
import select
import sys
import termios
import threading
import time
import tty

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import host  # noqa: E402


class FakeUnit(threading.Thread):
    """Behaviour as the host reads the manual (see READINGS.md)."""

    def __init__(self, address="0", at_step=0, qsize=96, speedup=50.0, faults=None,
                 qid="25020304", lose_steps=False, counts_refused=False):
        super().__init__(daemon=True)
        self.master, slave = pty.openpty()
        tty.setraw(self.master)
        self.path = os.ttyname(slave)
        self.slave = slave
        self.address = address
        self.at_step = at_step
        self.qsize = qsize
        self.speedup = speedup
        self.faults = faults or {}     # {(cmdletter, n-th occurrence): kind}
        self.counts = {}
        self.qid = qid
        self.lose_steps = lose_steps
        self.counts_refused = counts_refused
        self.stop = False
        self.executed = []             # vectors whose motion ran
        self.fired = []                # faults that were applied
        self.full_answers = 0
        self.received = []             # all complete frames
        self.lock = threading.Lock()
        self.reset()

    def reset(self):
        self.st = [0] * 7
        self.st[2] = 0x2B if self.address == "1" else 0
        self.pos = [0, 0, 0]
        self.queue = []
        self.cur = None                # (vec, end_time)
        self.index = 0
        self.V = 1000
        self.mode = "F"
        self.last = None

    # motion simulation
    def tick(self):
        now = time.monotonic()
        while True:
            if self.cur is None:
                if not self.queue:
                    return
                vec = self.queue.pop(0)
                dur = max(abs(c) for c in vec) / float(self.V) / self.speedup
                self.cur = (vec, now + dur)
            if now < self.cur[1]:
                return
            vec = self.cur[0]
            if self.lose_steps and any(vec):
                vec = (vec[0] + 1,) + tuple(vec[1:])
            self.pos = [a + b for a, b in zip(self.pos, vec)]
            if any(self.cur[0]):
                self.executed.append(self.cur[0])
            self.cur = None

    def running(self):
        return self.cur is not None or bool(self.queue)

    def answer(self, s):
        os.write(self.master, s.encode("latin-1") + b"\r")

    def handle(self, text):
        """text: frame without '!' and CR. Returns answer string or None."""
        if not text.startswith(self.address):
            return None
        ans = self.handle1(text)
        body = text[len(self.address):]
        if ans and not body.startswith("@") and not body.startswith(">"):
            if ans[:1] in ("0", "8") or self.counts_refused:
                self.index = (self.index + 1) % 256
        return ans

    def handle1(self, text):
        body = text[len(self.address):]
        self.received.append(body)
        inta = 8 if (self.st[6] & 0x80) else 0
        for cmd in ("PF", "SR", "SW", "XA", "ER", "EW", "?", "Q", "@", "F", "L", "C", "V",
                    "T", "A", "B", "$", "M", "N", "P", "D", "G", "H", "J", "K", "R", ">"):
            if body.startswith(cmd):
                arg = body[len(cmd):]
                break
        else:
            return "%X" % (3 | inta)
        if cmd != "@" and cmd != ">":
            pass
        try:
            if cmd in ("L", "C"):
                v = tuple(int(x) for x in arg.split(","))
                if len(v) != 3:
                    return "%X" % (4 | inta)
                if any(abs(c) > 65535 for c in v):
                    return "%X" % (5 | inta)
                if cmd == "L" and self.running():
                    return "%X" % (1 | inta)
                if len(self.queue) + (1 if self.cur else 0) >= self.qsize:
                    return "%X" % (1 | inta)
                self.queue.append(v)
                return "%X" % inta
            if cmd == "@":
                self.index = (self.index + self.at_step) % 256
                return "0,%02X" % self.index
            if cmd == ">":
                return self.last
            if cmd == "?":
                return "0,Ip54v3 21.12.2007"
            if cmd == "Q":
                return "0," + self.qid
            if cmd == "F":
                f = self.st[6] & ~0x60
                if self.running():
                    f |= 0x40
                if len(self.queue) + (1 if self.cur else 0) >= self.qsize:
                    f |= 0x20
                return "0,%02X" % f
            if cmd == "PF":
                return "%X,%d,%d,%d" % (inta, *self.pos)
            if cmd == "P":
                return "%X,%d,%d" % (inta, *self.pos[:2])
            if cmd == "SR":
                n = int(arg)
                if not 0 <= n <= 6:
                    return "5"
                return "%X,%02X" % (inta, self.st[n])
            if cmd == "SW":
                n, x = arg.split(",")
                n, x = int(n, 16), int(x, 16)
                if not 0 <= n <= 6 or not 0 <= x <= 255:
                    return "%X" % (5 | inta)
                self.st[n] = x
                return "%X" % inta
            if cmd == "V":
                n = int(arg)
                if not 40 <= n <= 50000:
                    return "%X" % (5 | inta)
                self.V = n
                return "%X" % inta
            if cmd == "T":
                n = int(arg)
                return "%X" % ((5 if not 1 <= n <= 24 else 0) | inta)
            if cmd == "M":
                if arg not in ("U", "D", "2", "4", "8", "F"):
                    return "%X" % (5 | inta)
                if self.running():
                    return "%X" % (7 | inta)
                return "%X" % inta
            if cmd in ("A", "B", "$"):
                int(arg)
                return "%X" % inta
            if cmd == "N":
                if self.running():
                    return "%X" % (7 | inta)
                self.pos = [0, 0, 0]
                return "%X" % inta
            return "%X" % inta
        except ValueError:
            return "%X" % (4 | inta)

    def run(self):
        buf = b""
        started = None
        silent_until = 0
        while not self.stop:
            r, _, _ = select.select([self.master], [], [], 0.005)
            with self.lock:
                self.tick()
            if r:
                try:
                    data = os.read(self.master, 4096)
                except OSError:
                    return
                if time.monotonic() < silent_until:
                    continue
                buf += data
            # watchdog for a frame that did not arrive in time [manual error 2]
            if buf and b"!" in buf and b"\r" not in buf:
                if started is None:
                    started = time.monotonic()
                elif time.monotonic() - started > 0.15:
                    buf = b""
                    started = None
                    self.answer("2")
                continue
            while b"\r" in buf:
                fr, _, buf = buf.partition(b"\r")
                started = None
                if b"!" not in fr:
                    continue
                fr = fr[fr.rindex(b"!") + 1:]
                text = fr.decode("latin-1")
                letter = text[len(self.address):][:1]
                key = letter
                self.counts[key] = self.counts.get(key, 0) + 1
                fault = self.faults.get((key, self.counts[key]))
                if fault:
                    self.fired.append(fault)
                if fault == "interrupt":
                    with self.lock:
                        self.st[6] |= 0x80
                        self.queue = []
                if fault == "cut":          # the tail of the frame is lost on the line
                    buf = b"!" + fr[: max(2, len(fr) // 2)]
                    started = time.monotonic()
                    continue
                if key == "@" and getattr(self, "arm_at", False):
                    self.arm_at = False     # the next '@' frame is lost too
                    continue
                if fault == "drop_frame":
                    continue
                if fault == "drop_answer_and_next_at":
                    self.arm_at = True
                    fault = "drop_answer"
                if fault == "restart":
                    with self.lock:
                        self.reset()
                    silent_until = time.monotonic() + 0.4
                    continue
                with self.lock:
                    ans = self.handle(text)
                if ans is None:
                    continue
                if ans in ("1", "9") and letter in "LC":
                    self.full_answers += 1
                if not text[len(self.address):].startswith(">"):
                    self.last = ans
                if fault == "drop_answer":
                    continue
                if fault == "flip":          # plausible damage: '0' becomes '1'
                    ans = "1" + ans[1:]
                if fault == "damage":
                    ans = "\xb0" + ans[1:] + "\x07"
                self.answer(ans)

    def close(self):
        self.stop = True
        self.join(1)
        os.close(self.master)
        os.close(self.slave)


JOB = os.path.join(HERE, "given", "square.job")
results = []


def check(name, ok, detail=""):
    ok = bool(ok)
    results.append(ok)
    print("%s  %s%s" % ("PASS" if ok else "FAIL", name, ("  (" + detail + ")") if detail and not ok else ""))


def run_host(unit, job=JOB, extra=()):
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        rc = host.main([unit.path, job, "--timeout", "0.3", "--pause", "5"] + list(extra))
    return rc, out.getvalue()


def job_vectors(path):
    return [j[1] for j in host.read_job(path) if j[0] == "M" and any(j[1])]


def scenario(name, faults=None, job=JOB, expect_rc=0, want_stat=None, **kw):
    u = FakeUnit(faults=faults, **kw)
    u.start()
    try:
        rc, out = run_host(u, job)
    finally:
        u.close()
    want = job_vectors(job)
    if len(u.fired) != len(faults or {}):
        check(name, False, "not all faults fired: %s" % u.fired)
        return u, out
    if want_stat and ("'%s'" % want_stat) not in out:
        check(name, False, "recovery path %s not taken: %s" % (want_stat, out[-300:]))
        return u, out
    if expect_rc == 0:
        ok = rc == 0 and u.executed == want
    else:
        ok = rc != 0 and len(u.executed) <= len(want) and \
            all(u.executed.count(v) <= want.count(v) for v in u.executed)
    check(name, ok, "rc=%s executed=%d/%d out=%s" % (rc, len(u.executed), len(want),
                                                     out.strip().splitlines()[-1:]))
    return u, out


def main():
    # -- the manual's worked examples: frames
    check("frame !0L1000,1000,20", host.frame("0", "L", [1000, 1000, 20]) == b"!0L1000,1000,20\r")
    check("frame !0C1000,1000,20", host.frame("0", "C", [1000, 1000, 20]) == b"!0C1000,1000,20\r")
    check("frame !0T5 / !0V10000 / !0A50", host.frame("0", "T", [5]) == b"!0T5\r"
          and host.frame("0", "V", [10000]) == b"!0V10000\r" and host.frame("0", "A", [50]) == b"!0A50\r")
    check("frame !1PF / !0SW8,F1", host.frame("1", "PF") == b"!1PF\r"
          and host.frame("0", "SW", ["8", "F1"]) == b"!0SW8,F1\r")
    # -- the manual's worked examples: answers
    check("answer '0' = OK", host.parse_answer(b"0") == (0, []))
    check("answer '0,-1000,2000,50' (PF)", host.parse_answer(b"0,-1000,2000,50") == (0, ["-1000", "2000", "50"]))
    check("answer '1' = queue full", host.parse_answer(b"1") == (1, []))
    a = host.parse_answer(b"8")
    check("answer '8' = OK but INTA=1", a is not None and a[0] & 7 == 0 and a[0] & 8)
    check("answer '5' = parameter out of range", host.parse_answer(b"5") == (5, []))
    check("answer '0,2B' (SR2)", host.parse_answer(b"0,2B") == (0, ["2B"]))
    check("damaged answer rejected", host.parse_answer(b"\xb00") is None and host.parse_answer(b"x") is None
          and host.parse_answer(b"") is None)
    # -- the table of examples against the fake unit, over the pty
    u = FakeUnit(address="0")
    u.start()
    u1 = FakeUnit(address="1")
    u1.start()
    try:
        ln = host.Line(u.path, 115200)
        ln1 = host.Line(u1.path, 115200)

        def ex(line, b):
            line.write(b)
            return line.readline(1.0)
        check("unit: !0L1000,0,0 -> 0", ex(ln, b"!0L1000,0,0\r") == b"0")
        time.sleep(0.1)
        u1.pos = [-1000, 2000, 50]
        check("unit: !1PF -> 0,-1000,2000,50", ex(ln1, b"!1PF\r") == b"0,-1000,2000,50")
        u.speedup = 0.0001
        for i in range(96):
            ex(ln, b"!0C100,20,0\r")
        check("unit: !0C100,20,0 on full queue -> 1", ex(ln, b"!0C100,20,0\r") == b"1")
        u.st[6] |= 0x80
        check("unit: !0V1000 while INTA=1 -> 8", ex(ln, b"!0V1000\r") == b"8")
        u.st[6] = 0
        check("unit: !0SW8,F1 -> 5", ex(ln, b"!0SW8,F1\r") == b"5")
        check("unit: !1SR2 -> 0,2B", ex(ln1, b"!1SR2\r") == b"0,2B")
        check("unit: other address ignored", ex(ln, b"!1F\r") is None)
        ln.close()
        ln1.close()
    finally:
        u.close()
        u1.close()

    # -- planning
    st = host.plan(host.read_job(JOB), 10.0)
    kinds = [s[0] for s in st if s[0] != "V"]
    check("square corners are L vectors (90 deg)", kinds == ["L"] * 6, str(kinds))
    pieces = host.split_long((200000, -70000, 5))
    check("long vector split into C-able pieces, exact sum",
          all(abs(c) <= 65535 for p in pieces for c in p) and
          tuple(map(sum, zip(*pieces))) == (200000, -70000, 5))

    # -- whole job runs
    with open(os.path.join(HERE, ".selftest-far.job"), "w") as f:
        f.write("speed 2000\n300,0,0\n0,300,0\n0,0,300\n100,100,100\n")
    u, out = scenario("clean run of square.job, every vector once")
    check("final position reported", "final position 0,0,0" in out, out[-200:])
    scenario("lost answer to a vector", faults={("L", 2): "drop_answer"})
    scenario("damaged answer to a vector", faults={("L", 3): "damage"})
    scenario("answer OK damaged into a plausible '1' (queue full)", faults={("L", 2): "flip"})
    scenario("unit restart while idle between vectors -> stop", expect_rc=1,
             faults={("F", 9): "restart"}, job=os.path.join(HERE, ".selftest-far.job"))
    scenario("frame cut short (watchdog error 2)", faults={("L", 4): "cut"})
    scenario("vector frame lost entirely", faults={("L", 1): "drop_frame"})
    scenario("lost answer to PF and damaged answer to @",
             faults={("P", 1): "drop_answer", ("@", 5): "damage"})
    scenario("index where '@' counts itself + lost answer", at_step=1,
             faults={("L", 2): "drop_answer", ("@", 4): "drop_answer"})
    scenario("lost '@' frame with self-counting '@' (position fallback)", at_step=1,
             faults={("L", 3): "drop_answer_and_next_at"},
             want_stat="position_checks")
    scenario("unit that indexes refused commands too + lost answer", counts_refused=True,
             faults={("L", 2): "drop_answer"},
             want_stat="position_checks")
    # many collinear vectors: C queue, queue-full answers, small queue
    path = os.path.join(HERE, ".selftest-line.job")
    with open(path, "w") as f:
        f.write("speed 20000\n" + "100,10,0\n" * 40 + "-4000,-400,0\n")
    u, out = scenario("C queue kept fed without overflow (queue of 8)", job=path, qsize=8,
                      faults={("C", 7): "drop_answer", ("C", 20): "cut"})
    check("queue-full answers (1) were seen and waited out", u.full_answers > 0,
          str(u.full_answers))
    lpath = os.path.join(HERE, ".selftest-long.job")
    with open(lpath, "w") as f:
        f.write("speed 50000\n150000,-70000,3\n")
    u = FakeUnit(faults={("C", 1): "drop_answer"})
    u.start()
    try:
        rc, out = run_host(u, lpath)
    finally:
        u.close()
    os.unlink(lpath)
    check("vector longer than 65535 sent as L+C pieces, once each", rc == 0 and len(u.executed) == 3
          and tuple(map(sum, zip(*u.executed))) == (150000, -70000, 3)
          and [r[:1] for r in u.received if r[:1] in "LC" and r != "L0,0,0"][-1] == "C", out[-200:])
    import subprocess
    u = FakeUnit(address="3")
    u.start()
    try:
        pr = subprocess.run([sys.executable, os.path.join(HERE, "host.py"), u.path, JOB,
                             "--address", "3", "--baud", "9600"], capture_output=True,
                            text=True, timeout=120)
    finally:
        u.close()
    check("host.py as a command (--address 3 --baud 9600): exit 0, position printed",
          pr.returncode == 0 and "final position 0,0,0" in pr.stdout, pr.stdout[-200:] + pr.stderr[-200:])
    check("default baud is 115200 (crystal 115200*8*17)", host.DEFAULT_BAUD == 115200)
    scenario("unit restart during the job -> stop, nothing doubled", expect_rc=1,
             faults={("L", 3): "restart"})
    scenario("unit interrupted (INTA=1, answer 8) -> stop", expect_rc=1,
             faults={("L", 2): "interrupt"})
    scenario("unit loses steps -> non-zero exit", expect_rc=1, lose_steps=True)
    scenario("not a GVE54 identity -> non-zero exit", expect_rc=1, qid="hello")
    os.unlink(path)
    os.unlink(os.path.join(HERE, ".selftest-far.job"))
    print("%d/%d checks passed" % (sum(results), len(results)))
    return 0 if all(results) else 1


if __name__ == "__main__":
    sys.exit(main())
