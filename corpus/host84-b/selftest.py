#!/usr/bin/env python3
"""selftest.py - tests host.py against a fake GVE84 over a pseudo-terminal pair.

The fake implements the manual's chapter 12 as READINGS.md reads it.
Prints PASS/FAIL per check; exit 0 when all pass.
"""
import os
import pty
import re
import select
import subprocess
import sys
import tempfile
import threading
import time
import tty

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import host  # noqa: E402

RESULTS = []


def check(name, cond, detail=""):
    RESULTS.append(bool(cond))
    print("%s  %s%s" % ("PASS" if cond else "FAIL", name, ("  -- " + detail) if (detail and not cond) else ""))
    sys.stdout.flush()


def cs(text):
    return "%02X" % (sum(text.encode()) % 256)


# ------------------------------------------------------------------ fake unit
class FakeGVE84(threading.Thread):
    SPEEDUP = 20.0      # simulated seconds per real second
    WATCHDOG = 0.2      # incomplete command -> error 2 after this long [R11]
    BOOT = 0.6          # silent time after a reset (manual: "cca po 2s") scaled

    def __init__(self, address=0, faults=None, at_counts=False, echo_repeat=False, repeat_reruns=False):
        super().__init__(daemon=True)
        self.master, self.slave = pty.openpty()
        tty.setraw(self.slave)
        self.path = os.ttyname(self.slave)
        self.address = str(address)
        self.faults = faults or []
        self.at_counts = at_counts
        self.echo_repeat = echo_repeat
        self.repeat_reruns = repeat_reruns
        self.received = []          # every line received (text)
        self.sent = []              # every answer sent (text)
        self.executed = []          # vectors taken into the queue
        self.stop = False
        self.counts = {}
        self.restarts = 0
        self.max_depth = 0
        self.reset()
        self.silent_until = 0.0

    # state after power-on / J (12.4)
    def reset(self):
        self.cs = False
        self.idx = 0
        self.last_cmd = None
        self.last_ans = "0"
        self.V = 1000
        self.T = 5
        self.pos = [0, 0, 0]
        self.queue = []             # pending (vec, speed)
        self.cur = None             # (vec, t0, dur)
        self.inta = False
        self.packet = None

    # -- motion simulation
    def sim(self):
        now = time.monotonic()
        while self.cur and now >= self.cur[1] + self.cur[2]:
            v, t0, d = self.cur
            self.pos = [a + b for a, b in zip(self.pos, v)]
            if self.queue:
                nv, sp = self.queue.pop(0)
                self.cur = (nv, t0 + d, self.dur(nv, sp))
            else:
                self.cur = None
        return now

    def dur(self, v, speed):
        return max(abs(c) for c in v) / float(speed) / self.SPEEDUP

    def position(self):
        now = self.sim()
        if not self.cur:
            return list(self.pos)
        v, t0, d = self.cur
        f = min(1.0, (now - t0) / d) if d else 1.0
        return [p + int(c * f) for p, c in zip(self.pos, v)]

    def running(self):
        self.sim()
        return self.cur is not None

    def start_or_queue(self, v):
        self.sim()
        if self.cur is None:
            self.cur = (v, time.monotonic(), self.dur(v, self.V))
        else:
            self.queue.append((v, self.V))
        self.max_depth = max(self.max_depth, len(self.queue) + 1)
        self.executed.append(tuple(v))

    # -- protocol
    def answer(self, text, fault=None):
        self.last_ans = text
        self.emit(text, fault)

    def emit(self, text, fault=None):
        if self.cs:
            text = text + "," + cs(text + ",")
        if fault == "drop_answer":
            self.sent.append("(dropped) " + text)
            return
        if fault == "corrupt_answer":
            # damage one character of the answer on the line
            t = list(text)
            t[0] = "1" if t[0] == "0" else "0"
            text = "".join(t)
        self.sent.append(text)
        os.write(self.master, (text + "\r").encode())

    def code(self, err):
        return "%X" % ((8 if self.inta else 0) | err)

    def fault_for(self, body):
        for f in self.faults:
            if re.fullmatch(f["match"], body):
                key = id(f)
                self.counts[key] = self.counts.get(key, 0) + 1
                if self.counts[key] in f.get("nth", [1]):
                    return f["action"]
        return None

    def handle(self, line):
        self.received.append(line)
        if time.monotonic() < self.silent_until:
            return
        i = line.rfind("!")
        if i < 0:
            return
        line = line[i:]
        if len(line) < 2 or line[1] != self.address:
            return
        raw = line[2:]
        body = raw
        cs_ok = True
        if self.cs:
            k = raw.rfind(",")
            if k < 0 or not re.fullmatch(r"[0-9A-F]{2}", raw[k + 1:]) or \
                    cs(line[:2 + k + 1]) != raw[k + 1:]:
                cs_ok = False
            else:
                body = raw[:k]
        fault = self.fault_for(body)
        if fault == "drop_command":
            return
        if body == ">" and cs_ok and self.repeat_reruns and self.last_cmd:
            return self.handle(self.last_cmd)   # the dangerous reading of '>'
        if body in ("@", ">") and cs_ok:
            if body == "@":
                if self.at_counts:
                    self.idx = (self.idx + 1) % 256
                self.emit("0,%02X" % self.idx, fault)
            else:
                if self.echo_repeat and self.last_cmd:
                    os.write(self.master, (self.last_cmd + "\r").encode())
                self.emit(self.last_ans, fault)
            return
        self.idx = (self.idx + 1) % 256
        self.last_cmd = line
        if not cs_ok:
            return self.answer(self.code(4), fault)
        if self.packet is not None and not body.startswith("*E"):
            err = self.execute(body)[0]
            self.packet.append(err)
            return
        err, params = self.execute(body)
        if err is None:
            return
        text = self.code(err) + "".join("," + p for p in params)
        if fault == "restart":
            self.reset()
            self.restarts += 1
            self.silent_until = time.monotonic() + self.BOOT
            return
        self.answer(text, fault)
        if body == "%-":
            pass

    def execute(self, b):
        m = re.fullmatch(r"([LC])(-?\d+),(-?\d+),(-?\d+)", b)
        if m:
            v = [int(g) for g in m.groups()[1:]]
            if any(abs(c) > 2147483647 for c in v):
                return 5, []
            self.sim()
            busy = self.cur is not None
            if m.group(1) == "L" and (busy or self.queue):
                return 1, []          # "Dokud není přijat, karta hlásí chybu 1"
            if len(self.queue) + (1 if busy else 0) >= 64:
                return 1, []
            self.start_or_queue(v)
            return 0, []
        if b == "?":
            return 0, ["IP84 v3 27.1.2010"]
        if b == "Q":
            return 0, ["25020304"]
        if b == "PF":
            return 0, [str(c) for c in self.position()]
        if b == "P":
            return 0, [str(c) for c in self.position()[:2]]
        if b == "F":
            run = self.running()
            full = len(self.queue) + (1 if run else 0) >= 64
            return 0, ["%02X" % ((0x80 if self.inta else 0) | (0x40 if run else 0) | (0x20 if full else 0))]
        if b == "%+":
            self.cs = True
            return 0, []
        if b == "%-":
            self.cs = False
            return 0, []
        m = re.fullmatch(r"T(\d+)", b)
        if m:
            n = int(m.group(1))
            if not 1 <= n <= 24:
                return 5, []
            self.T = n
            return 0, []
        m = re.fullmatch(r"V(\d+)", b)
        if m:
            n = int(m.group(1))
            if not 10 <= n <= 100000:
                return 5, []
            self.V = n
            return 0, []
        if b in ("VK", "VN"):
            return 0, []
        if b == "*S":
            self.packet = []
            return None, []
        m = re.fullmatch(r"\*E(\d+)", b)
        if m and self.packet is not None:
            errs = self.packet
            self.packet = None
            err = next((e for e in errs if e), 0)
            return err, [str(len(errs))]
        if b == "J":
            self.reset()
            self.silent_until = time.monotonic() + self.BOOT
            return None, []
        return 3, []

    def run(self):
        buf = b""
        first = None
        while not self.stop:
            r, _, _ = select.select([self.master], [], [], 0.02)
            if r:
                try:
                    d = os.read(self.master, 1024)
                except OSError:
                    return
                if d and first is None:
                    first = time.monotonic()
                buf += d
                while b"\r" in buf:
                    line, buf = buf.split(b"\r", 1)
                    first = time.monotonic() if buf else None
                    text = line.decode("ascii", "replace")
                    if self.fault_for_lost_cr(text):
                        buf = line + buf    # CR "lost": line stays incomplete
                        first = time.monotonic()
                        break
                    self.handle(text)
            elif buf and first and time.monotonic() - first > self.WATCHDOG:
                # "příkaz nepřišel celý včas ... (zafunguje WATCH DOG)"
                self.received.append(buf.decode("ascii", "replace") + "(incomplete)")
                self.idx = (self.idx + 1) % 256
                self.last_cmd = buf.decode("ascii", "replace")
                self.answer(self.code(2))
                buf = b""
                first = None

    lost_cr = None   # regex of a line whose CR gets lost once

    def fault_for_lost_cr(self, text):
        if self.lost_cr and re.search(self.lost_cr, text):
            self.lost_cr = None
            return True
        return False


# ------------------------------------------------------------------ helpers
TMPDIR = tempfile.mkdtemp(prefix=".selftest-", dir=HERE)


def write_job(text):
    fd, path = tempfile.mkstemp(suffix=".job", dir=TMPDIR)
    os.write(fd, text.encode())
    os.close(fd)
    return path


SQUARE = os.path.join(HERE, "given", "square.job")


def run_host(fake, job, *opts, timeout=60):
    fake.start()
    p = subprocess.run([sys.executable, os.path.join(HERE, "host.py"), fake.path, job] + list(opts),
                       capture_output=True, text=True, timeout=timeout)
    fake.stop = True
    return p


def executed_sum(fake):
    return tuple(sum(c) for c in zip((0, 0, 0), *[v for v in fake.executed if v != (0, 0, 0)]))


def job_vectors(path):
    return [v for t, v in host.load_job(path) if t == "vec"]


# ------------------------------------------------------------------ checks
def manual_examples():
    # 12.3.2 worked example: !0A100, = 0x14F -> !0A100,4F
    u = host.Unit(-1, 0)
    u.cs = True
    check("manual: !0A100 with checksum is !0A100,4F", u.frame("A100") == "!0A100,4F\r")
    check("manual: !0%- with checksum is !0%-,CF", u.frame("%-") == "!0%-,CF\r")
    check("manual: !0*S,FA and !0*E10,4D", u.frame("*S") == "!0*S,FA\r" and u.frame("*E10") == "!0*E10,4D\r")
    lines = {"C697,30,0": "51", "C692,92,0": "54", "C682,151,0": "7F", "C665,209,0": "84",
             "C645,268,0": "87", "C619,322,0": "7F", "C589,375,0": "8D", "C553,425,0": "80",
             "C515,471,0": "7F", "C471,515,0": "7F"}
    check("manual: the 10 packet vector checksums",
          all(u.frame(b) == "!0%s,%s\r" % (b, c) for b, c in lines.items()))
    a = u.parse(b"0,5C")
    check("manual: answer 0,5C to %+ is OK with valid checksum", a.err == 0 and a.fields == [])
    a = u.parse(b"0,10,E9")
    check("manual: packet answer 0,10,E9 = OK, 10 commands", a.err == 0 and a.fields == ["10"])
    bad = False
    try:
        u.parse(b"0,11,E9")
    except host.BadAnswer:
        bad = True
    check("damaged checksummed answer is rejected", bad)
    u.cs = False
    t = [(b"0", 0, False, []), (b"0,-1000,2000,50", 0, False, ["-1000", "2000", "50"]),
         (b"1", 1, False, []), (b"8", 0, True, []), (b"5", 5, False, []), (b"0,2B", 0, False, ["2B"])]
    check("manual: 12.6 answer table parses (0, PF, 1, 8=INTA, 5, SR2)",
          all((lambda a: (a.err, a.inta, a.fields) == (e, i, f))(u.parse(r)) for r, e, i, f in t))
    check("manual: default address frame !0L1000,1000,20", u.frame("L1000,1000,20") == "!0L1000,1000,20\r")


def square(opts, name, **kw):
    fake = FakeGVE84(**kw)
    p = run_host(fake, SQUARE, *opts)
    want = tuple(sum(c) for c in zip(*job_vectors(SQUARE)))
    ok = p.returncode == 0 and executed_sum(fake) == want and \
        len([v for v in fake.executed if v != (0, 0, 0)]) == len(job_vectors(SQUARE))
    check(name, ok, "rc=%d out=%r err=%r" % (p.returncode, p.stdout[-300:], p.stderr[-300:]))
    return fake, p


def main():
    manual_examples()

    f, p = square([], "square.job runs, plain link")
    check("host identifies the unit with ? and Q",
          any(l.startswith("!0?") for l in f.received) and any(l.startswith("!0Q") for l in f.received))
    check("host sets dwell T and waits with L0,0,0 end marker",
          any(l.startswith("!0T10") for l in f.received) and any(l.startswith("!0L0,0,0") for l in f.received))
    check("host reports final position", "final position 0,0,0" in p.stdout, p.stdout)

    f, p = square(["--checksums"], "square.job runs with --checksums")
    check("checksums switched on with plain !0%+ then all frames checksummed",
          "!0%+" in f.received and all(re.search(r",[0-9A-F]{2}$", l) for l in
                                       f.received[f.received.index("!0%+") + 1:]))

    # lost answer to a vector (plain and with checksums): must not move twice
    square([], "lost answer to a vector (plain): executed once",
           faults=[{"match": r"L400,0,0", "action": "drop_answer"}])
    square(["--checksums"], "lost answer to a vector (checksums): executed once",
           faults=[{"match": r"L0,400,0", "action": "drop_answer", "nth": [1]}])
    # damaged answer with checksums on
    f, p = square(["--checksums"], "damaged answer to a vector (checksums): executed once",
                  faults=[{"match": r"L-400,0,0", "action": "corrupt_answer", "nth": [1]}])
    check("damaged answer recovered through @ and >",
          any(l.startswith("!0@") for l in f.received) and any(l.startswith("!0>") for l in f.received))
    f, p = square([], "damaged answer to a vector, plain line ('0' read as '1'): confirmed by >, executed once",
                  faults=[{"match": r"L0,-400,0", "action": "corrupt_answer", "nth": [1]}])
    # lost command: must be re-sent
    f, p = square(["--checksums"], "lost command (never reached unit) is re-sent",
                  faults=[{"match": r"L0,-400,0", "action": "drop_command"}])
    # lost answer of a repeat and of an index query
    square(["--checksums"], "lost answers to @ and > themselves",
           faults=[{"match": r"L200,200,50", "action": "drop_answer"},
                   {"match": r"@", "action": "drop_answer", "nth": [3]},
                   {"match": r">", "action": "drop_answer", "nth": [1]}])
    # lost CR -> watchdog error 2 -> re-send
    fk = FakeGVE84()
    fk.lost_cr = r"L-200,-200,-50"
    fk.start()
    p = subprocess.run([sys.executable, os.path.join(HERE, "host.py"), fk.path, SQUARE, "--checksums"],
                       capture_output=True, text=True, timeout=60)
    fk.stop = True
    check("lost CR (watchdog answer 2) re-sent, executed once",
          p.returncode == 0 and executed_sum(fk) == (0, 0, 0) and fk.executed.count((-200, -200, -50)) == 1,
          p.stderr[-300:])
    # > echoing the command text (alternative reading R8)
    square(["--checksums"], "repeat answer with echoed command text",
           echo_repeat=True, faults=[{"match": r"L400,0,0", "action": "drop_answer"}])
    # @ counting itself (alternative reading R6): falls back to position
    square(["--checksums"], "'@' counting itself: position fallback, executed once",
           at_counts=True, faults=[{"match": r"L0,400,0", "action": "drop_answer"}])

    f, p = square(["--checksums"], "'>' that re-runs commands is detected; lost answer settled by position",
                  repeat_reruns=True, faults=[{"match": r"L0,400,0", "action": "drop_answer"}])
    check("'>' re-run detection printed a note", "re-run" in p.stdout, p.stdout)
    square([], "'>' that re-runs commands, plain line: no confirmation by '>', executed once",
           repeat_reruns=True)

    # packets: the manual's example packet appears exactly on the line
    man = [(697, 30, 0), (692, 92, 0), (682, 151, 0), (665, 209, 0), (645, 268, 0),
           (619, 322, 0), (589, 375, 0), (553, 425, 0), (515, 471, 0), (471, 515, 0)]
    job = write_job("speed 20000\n697,30,0\n" + "".join("%d,%d,%d\n" % v for v in man))
    fk = FakeGVE84()
    p = run_host(fk, job, "--checksums", "--packets", "--packet-size", "10")
    expect = ["!0*S,FA"] + ["!0C%d,%d,%d,%s" % (v + (cs("!0C%d,%d,%d," % v),)) for v in man] + ["!0*E10,4D"]
    r = fk.received
    found = any(r[i:i + 12] == expect for i in range(len(r)))
    check("packets: manual's example packet sent verbatim and run", p.returncode == 0 and found,
          p.stderr[-300:])
    check("packets: unit answered 0,10,E9 as in the manual", "0,10,E9" in fk.sent)
    want = tuple(sum(c) for c in zip((697, 30, 0), *man))
    check("packets: final position correct", executed_sum(fk) == want and len(fk.executed) == 12)

    # packets with a lost packet answer
    fk = FakeGVE84(faults=[{"match": r"\*E10", "action": "drop_answer"}])
    p = run_host(fk, job, "--checksums", "--packets", "--packet-size", "10")
    check("packets: lost packet answer, executed once", p.returncode == 0 and len(fk.executed) == 12,
          p.stderr[-300:])

    # long continuous job that overflows the 64-vector queue
    vecs = ["%d,%d,0" % (100, 3 * (i % 2)) for i in range(150)]
    job2 = write_job("speed 500\n" + "\n".join(vecs) + "\n")
    fk = FakeGVE84()
    p = run_host(fk, job2, "--checksums")
    check("150 continuous vectors through a 64-deep queue (queue full = 1)",
          p.returncode == 0 and len([v for v in fk.executed if v != (0, 0, 0)]) == 150, p.stderr[-300:])
    check("the queue really filled (depth reached 64, unit answered 1)",
          fk.max_depth == 64 and "1,5D" in fk.sent, "max depth %d" % fk.max_depth)
    fk = FakeGVE84()
    p = run_host(fk, job2, "--checksums", "--packets")
    check("150 continuous vectors in packets",
          p.returncode == 0 and len([v for v in fk.executed if v != (0, 0, 0)]) == 150, p.stderr[-300:])
    check("packets kept the queue fed but never overflowing (no error 1 to a packet)",
          30 <= fk.max_depth <= 64 and not any(re.match(r"1,\d+,", a) for a in fk.sent),
          "max depth %d" % fk.max_depth)

    # unit restart in the middle: must stop, non-zero, one line, no re-send
    fk = FakeGVE84(faults=[{"match": r"L-400,0,0", "action": "restart"}])
    p = run_host(fk, SQUARE, "--checksums")
    check("unit restart mid-job: non-zero exit with one-line reason",
          p.returncode != 0 and len(p.stderr.strip().splitlines()) == 1 and "restart" in p.stderr,
          "rc=%d err=%r" % (p.returncode, p.stderr))
    check("unit restart mid-job: no vector sent after the restart",
          fk.executed == [] or (-400, 0, 0) not in fk.executed[2:], str(fk.executed))
    # restart during setup (before any vector): host sets up again and completes
    fk = FakeGVE84(faults=[{"match": r"VK", "action": "restart"}])
    p = run_host(fk, SQUARE, "--checksums", timeout=90)
    check("unit restart during setup: host re-connects and completes", p.returncode == 0,
          "rc=%d err=%r" % (p.returncode, p.stderr))

    # restart without checksums: detected by the index, non-zero
    fk = FakeGVE84(faults=[{"match": r"L-400,0,0", "action": "restart"}])
    p = run_host(fk, SQUARE)
    check("unit restart mid-job, plain link: non-zero, one line",
          p.returncode != 0 and len(p.stderr.strip().splitlines()) == 1, "rc=%d err=%r" % (p.returncode, p.stderr))

    # unit left with checksums on by an earlier session; host without --checksums
    fk = FakeGVE84()
    fk.cs = True
    p = run_host(fk, SQUARE)
    check("unit already in checksum mode: host switches it off (!0%-,CF) and runs",
          p.returncode == 0 and "!0%-,CF" in fk.received and not fk.cs, p.stderr)

    # wrong address: no answer -> non-zero
    fk = FakeGVE84(address=3)
    p = run_host(fk, SQUARE)
    check("no unit at address 0: non-zero with reason", p.returncode != 0 and "no answer" in p.stderr,
          p.stderr)
    fk = FakeGVE84(address=3)
    p = run_host(fk, SQUARE, "--address", "3")
    check("--address 3 talks to unit 3", p.returncode == 0, p.stderr)

    n = len(RESULTS)
    bad = RESULTS.count(False)
    print("%d checks, %d failed" % (n, bad))
    return 0 if bad == 0 else 1


if __name__ == "__main__":
    try:
        rc = main()
    finally:
        import shutil
        shutil.rmtree(TMPDIR, ignore_errors=True)
    sys.exit(rc)
