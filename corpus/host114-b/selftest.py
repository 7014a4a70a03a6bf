#!/usr/bin/env python3
"""Self test: host.py against a fake GVE114 over a pseudo-terminal pair.
Prints PASS/FAIL per check; exit 0 when all pass.  Standard library only."""
import collections
import os
import pty
import select
import shutil
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

RESULTS = []


def check(name, ok, info=""):
    RESULTS.append(ok)
    print("%s  %s%s" % ("PASS" if ok else "FAIL", name, ("" if ok else "   -> " + str(info))))


def cs(text):
    return sum(text.encode()) & 0xFF


# ====================================================================== fake unit
class FakeGVE114(threading.Thread):
    """Small model of the unit as this host reads the manual (see READINGS.md).
    faults: dict name -> set of ordinals (1-based) of received C frames / packets."""

    def __init__(self, fd, cap=2048, speedup=20.0, faults=None, version="IP114/500 x16 16.9.2018",
                 at_counts=False, address=0, count_queries=True):
        super().__init__(daemon=True)
        self.fd = fd
        self.cap = cap
        self.speedup = speedup
        self.faults = {k: set(v) for k, v in (faults or {}).items()}
        self.version = version
        self.at_counts = at_counts
        self.address = address
        self.count_queries = count_queries
        self.stop = False
        self.executed = []          # every vector the unit accepted (L and C, non-zero)
        self.frames = []            # every complete frame text received
        self.cframes = 0
        self.packets_seen = 0
        self.restarts = 0
        self.lock = threading.Lock()
        self.reset_state()

    def reset_state(self):
        self.checks = False
        self.idx = 0
        self.pos = [0, 0, 0, 0]
        self.queue = collections.deque()
        self.cur = None             # (vec, t0, dur, startpos)
        self.V = 1000
        self.inta = 0
        self.in_packet = False
        self.last_answer = b"0\r"
        self.buf = b""
        self.deaf_until = 0

    # ---- motion
    def tick(self):
        now = time.monotonic()
        while True:
            if self.cur is None:
                if not self.queue:
                    return
                vec, v = self.queue.popleft()
                dur = max(abs(c) for c in vec) / float(v) / self.speedup
                self.cur = (vec, now, dur, list(self.pos))
            vec, t0, dur, sp = self.cur
            if now - t0 >= dur:
                self.pos = [sp[i] + vec[i] for i in range(4)]
                self.cur = None
                continue
            return

    def cur_pos(self):
        if self.cur is None:
            return self.pos
        vec, t0, dur, sp = self.cur
        f = min(1.0, (time.monotonic() - t0) / dur) if dur else 1.0
        return [sp[i] + int(vec[i] * f) for i in range(4)]

    def busy(self):
        return self.cur is not None or bool(self.queue)

    def nqueued(self):
        return len(self.queue) + (1 if self.cur else 0)

    # ---- io
    def send(self, text):
        if self.checks:
            text = text + ",%02X" % cs(text + ",")
        data = text.encode() + b"\r"
        self.last_answer = data
        os.write(self.fd, data)

    def run(self):
        while not self.stop:
            with self.lock:
                self.tick()
            r, _, _ = select.select([self.fd], [], [], 0.003)
            if not r:
                continue
            try:
                d = os.read(self.fd, 4096)
            except OSError:
                time.sleep(0.01)
                continue
            if time.monotonic() < self.deaf_until:
                continue                       # restarting: deaf
            self.buf += d
            while b"\r" in self.buf:
                line, self.buf = self.buf.split(b"\r", 1)
                k = line.rfind(b"!")
                if k < 0:
                    continue                   # noise without frame start
                with self.lock:
                    self.frame(line[k:].decode("ascii", "replace"))

    # ---- protocol
    def frame(self, text):
        self.frames.append(text)
        if len(text) < 3 or not text[1].isdigit():
            return
        if int(text[1]) != self.address:
            return                                     # not for us: silent
        body = text[2:]
        is_c = body.startswith("C")
        if is_c:
            self.cframes += 1
            n = self.cframes
            if n in self.faults.get("drop_frame", ()):
                return                                 # lost on the line entirely
            if n in self.faults.get("cut_frame", ()):
                time.sleep(0.05)                       # watchdog fires
                self.idx = (self.idx + 1) & 0xFF
                self.send("%X" % (self.inta << 3 | 2))
                return
            if n in self.faults.get("damage_frame", ()):
                # a digit damaged on the line: '4' -> '5' etc.
                for i, ch in enumerate(text):
                    if ch.isdigit() and i > 3:
                        text = text[:i] + chr(ord(ch) ^ 0x01) + text[i + 1:]
                        body = text[2:]
                        break
            if n in self.faults.get("restart", ()):
                self.restarts += 1
                self.reset_state()
                self.deaf_until = time.monotonic() + 0.3
                return
        if self.checks:
            k = body.rfind(",")
            ok = k >= 0 and len(body) - k - 1 == 2
            if ok:
                try:
                    ok = int(body[k + 1:], 16) == cs(text[:len(text) - len(body) + k + 1])
                except ValueError:
                    ok = False
            if not ok:
                if not body.startswith(">") and not body.startswith("@"):
                    self.idx = (self.idx + 1) & 0xFF
                self.reply(4, [], is_c)
                return
            body = body[:k]
        if body.startswith("@"):
            if self.at_counts:
                self.idx = (self.idx + 1) & 0xFF
            self.reply(0, [str(self.idx)], False)
            return
        if body.startswith(">"):
            os.write(self.fd, self.last_answer)
            return
        if self.count_queries or body not in ("F", "PF", "P", "?", "Q", "SR6"):
            self.idx = (self.idx + 1) & 0xFF
        if self.in_packet:
            if body.startswith("*E"):
                self.in_packet = False
                self.packets_seen += 1
                pn = self.packets_seen
                code = self.perr or 0
                if pn in self.faults.get("drop_packet_answer", ()):
                    return
                self.reply(code, [str(self.pk)], False)
                return
            if self.perr is None:
                c, _ = self.execute(body)
                if c:
                    self.perr = c
                else:
                    self.pk += 1
            return
        if body == "*S":
            self.in_packet = True
            self.perr = None
            self.pk = 0
            return
        code, params = self.execute(body)
        self.reply(code, params, is_c)

    def reply(self, code, params, is_c):
        text = "%X" % (self.inta << 3 | code)
        if params:
            text += "," + ",".join(params)
        n = self.cframes
        if is_c and n in self.faults.get("drop_answer", ()):
            self.last_answer = (text + "\r").encode()
            return
        if is_c and n in self.faults.get("corrupt_answer", ()):
            if self.checks:
                text2 = text + ",%02X" % cs(text + ",")
            else:
                text2 = text
            flip = 0x40 if "garbage" in self.faults else 0x01
            bad = chr(ord(text2[0]) ^ flip) + text2[1:]      # one bit flipped on the line
            self.last_answer = (text2 + "\r").encode()
            os.write(self.fd, bad.encode() + b"\r")
            return
        self.send(text)

    def vec_args(self, s):
        p = [int(x) for x in s.split(",")]
        if not 3 <= len(p) <= 4:
            raise ValueError
        if len(p) == 3:
            p.append(0)
        if any(abs(c) > 2147483647 for c in p):
            raise OverflowError
        return tuple(p)

    def execute(self, b):
        try:
            if b == "?":
                return 0, [self.version]
            if b == "Q":
                return 0, ["25022504"]
            if b == "%+":
                self.checks = True
                return 0, []
            if b == "%-":
                self.checks = False
                return 0, []
            if b == "F" or b == "SR6":
                v = (self.inta << 7) | ((1 if self.busy() else 0) << 6)
                if b == "F" and self.nqueued() >= self.cap:
                    v |= 1 << 5
                return 0, ["%02X" % v]
            if b == "PF":
                p = self.cur_pos()
                return 0, [str(p[0]), str(p[1]), str(p[2])]
            if b == "P":
                p = self.cur_pos()
                return 0, [str(p[0]), str(p[1])]
            if b[0] in "VABT$" and b[1:].lstrip("-").isdigit():
                n = int(b[1:])
                if b[0] in "VB" and not 10 <= n <= 100000:
                    return 5, []
                if b[0] == "T" and not 1 <= n <= 24:
                    return 5, []
                if b[0] == "V":
                    self.V = n
                return 0, []
            if b[0] in "LC":
                vec = self.vec_args(b[1:])
                if b[0] == "L" and self.busy():
                    return 1, []
                if self.nqueued() >= self.cap:
                    return 1, []
                if any(vec):
                    self.executed.append(vec)
                    self.queue.append((vec, self.V))
                return 0, []
            if b == "J":
                self.reset_state()
                self.deaf_until = time.monotonic() + 0.3
                return 0, []
            return 3, []
        except OverflowError:
            return 5, []
        except (ValueError, IndexError):
            return 4, []


# ====================================================================== harness
def run_host(job, args, **fake_kw):
    mfd, sfd = pty.openpty()
    tty.setraw(sfd)
    tty.setraw(mfd)
    path = os.ttyname(sfd)
    fake = FakeGVE114(mfd, **fake_kw)
    fake.start()
    try:
        p = subprocess.run([sys.executable, os.path.join(HERE, "host.py"), path, job] + args,
                           capture_output=True, text=True, timeout=120)
    finally:
        fake.stop = True
        fake.join(1)
        os.close(sfd)
        os.close(mfd)
    return p, fake


def job_vectors(path):
    return [v for k, v in host.parse_job(path) if k == "vec"]


def final_ok(p, fake, vecs, name):
    exp = [sum(v[i] for v in vecs) for i in range(4)]
    ok = (p.returncode == 0 and fake.executed == vecs and fake.pos == exp)
    info = "rc=%s executed=%d/%d pos=%s exp=%s err=%s" % (
        p.returncode, len(fake.executed), len(vecs), fake.pos, exp, p.stderr.strip()[-300:])
    check(name, ok, info)


def main():
    # ---------------- worked examples from the manual
    check("manual 13.3.2: checksum of '!0A100,' is 4F", "%02X" % host.checksum("!0A100,") == "4F")
    check("manual 13.3.2: frame '!0A100' with checksum = '!0A100,4F<CR>'",
          host.build_frame(0, "A100", True) == b"!0A100,4F\r")
    check("manual 13.3.2: frame '!0%-' with checksum = '!0%-,CF<CR>'",
          host.build_frame(0, "%-", True) == b"!0%-,CF\r")
    check("manual 13.3.2: '!0%+' is sent without checksum",
          host.build_frame(0, "%+", False) == b"!0%+\r")
    check("manual 13.3.2: answer '0,5C' parses (checksum OK, code 0)",
          host.parse_answer(b"0,5C", True) == (0, 0, []))
    check("manual 13.3.2: answer '0' without checksums", host.parse_answer(b"0", False) == (0, 0, []))
    manual_packet = ["!0*S,FA", "!0C697,30,0,51", "!0C692,92,0,54", "!0C682,151,0,7F",
                     "!0C665,209,0,84", "!0C645,268,0,87", "!0C619,322,0,7F", "!0C589,375,0,8D",
                     "!0C553,425,0,80", "!0C515,471,0,7F", "!0C471,515,0,7F", "!0*E10,4D"]
    built = [host.build_frame(0, t[2:t.rfind(",")], True).decode().rstrip("\r")
             for t in manual_packet]
    check("manual 13.4: all 12 packet lines reproduce their checksums", built == manual_packet,
          built)
    check("manual 13.4: packet answer '0,10,E9' = OK, 10 commands",
          host.parse_answer(b"0,10,E9", True) == (0, 0, ["10"]))
    check("manual 13.8: '0,-1000,2000,50' (PF) = OK, x,y,z",
          host.parse_answer(b"0,-1000,2000,50", False) == (0, 0, ["-1000", "2000", "50"]))
    check("manual 13.8: '1' = vector not accepted (queue full)",
          host.parse_answer(b"1", False) == (0, 1, []))
    check("manual 13.8: '8' = OK but INTA=1", host.parse_answer(b"8", False) == (1, 0, []))
    check("manual 13.8: '5' = parameter out of range", host.parse_answer(b"5", False) == (0, 5, []))
    check("manual 13.8: '0,2B' (SR2) = OK, value 2B",
          host.parse_answer(b"0,2B", False) == (0, 0, ["2B"]))
    bad = []
    for raw in (b"0,5D", b"1,5C", b"0", b"", b"Z", b"0,-1000,20O0"):
        try:
            host.parse_answer(raw, True)
            bad.append(raw)
        except host.LineFault:
            pass
    check("damaged answers are rejected when checksums are on", not bad, bad)
    check("default baud is 115200 (manual: 'standardne ... 115 200 bd')", host.DEFAULT_BAUD == 115200)

    # ---------------- jobs
    sq = os.path.join(HERE, "given", "square4.job")
    sqv = job_vectors(sq)
    tmp = tempfile.mkdtemp(prefix=".selftest-", dir=HERE)
    long_job = os.path.join(tmp, "poly.job")
    with open(long_job, "w") as f:
        f.write("speed 4000\n")
        for i in range(30):
            f.write("%d,%d,%d,%d\n" % (100 + i, -50 + 7 * i, (i % 3) - 1, i % 2))
        f.write("speed 2500\n")
        for i in range(12):
            f.write("%d,%d,0,0\n" % (-300, 20 * i))
    lv = job_vectors(long_job)

    p, f = run_host(sq, [])
    final_ok(p, f, sqv, "square4.job, plain")
    check("host reports final position on stdout", "final position X,Y,Z = 0,0,0" in p.stdout,
          p.stdout)
    p, f = run_host(sq, ["--checksums"])
    final_ok(p, f, sqv, "square4.job, --checksums")
    p, f = run_host(sq, ["--checksums"], cap=2)
    final_ok(p, f, sqv, "queue of 2 (answer 1 = full, host waits, no overflow)")
    p, f = run_host(long_job, ["--packets"], cap=64)
    final_ok(p, f, lv, "42-vector job, --packets")
    p, f = run_host(long_job, ["--packets", "--checksums"], cap=64)
    final_ok(p, f, lv, "42-vector job, --packets --checksums")
    p, f = run_host(long_job, ["--packets", "--checksums"], cap=8)
    final_ok(p, f, lv, "packets into a queue of 8 (partial packet acceptance)")

    # ---------------- line faults
    p, f = run_host(sq, [], faults={"drop_answer": {3}})
    final_ok(p, f, sqv, "lost answer to vector 3 (index says received) -> not resent")
    p, f = run_host(sq, [], faults={"drop_frame": {2}})
    final_ok(p, f, sqv, "lost command frame (index unchanged) -> resent once")
    p, f = run_host(sq, ["--checksums"], faults={"corrupt_answer": {2}})
    final_ok(p, f, sqv, "damaged answer with checksums on -> detected, not resent")
    p, f = run_host(sq, [], faults={"corrupt_answer": {4}, "garbage": ()})
    final_ok(p, f, sqv, "damaged answer without checksums ('0' -> 'p') -> recovered")
    p, f = run_host(sq, [], faults={"corrupt_answer": {4}})
    final_ok(p, f, sqv, "no checksums, '0' damaged into '1' -> F says room -> settled by position")
    p, f = run_host(sq, [], faults={"restart": {3}})
    lines = [l for l in p.stderr.strip().splitlines() if l]
    check("unit restart mid-job, no checksums -> non-zero exit, nothing repeated",
          p.returncode != 0 and len(lines) == 1 and "restart" in lines[0]
          and f.executed == sqv[:2], "rc=%s stderr=%r executed=%s" % (p.returncode, p.stderr,
                                                                     f.executed))
    p, f = run_host(sq, ["--checksums"], faults={"cut_frame": {4}})
    final_ok(p, f, sqv, "frame cut short -> watchdog error 2 -> resent")
    p, f = run_host(sq, ["--checksums"], faults={"damage_frame": {2, 5}})
    final_ok(p, f, sqv, "damaged command frame with checksums -> refused by unit, resent")
    import random
    rnd = random.Random(114)
    for trial in range(4):
        fl = {}
        for name in ("drop_answer", "drop_frame", "cut_frame", "corrupt_answer", "damage_frame"):
            fl[name] = set(rnd.sample(range(1, 60), 4))
        p, f = run_host(long_job, ["--checksums"], cap=6, faults=fl)
        final_ok(p, f, lv, "random line faults, trial %d (%d faults, checksums, queue 6)" %
                 (trial + 1, sum(len(x) for x in fl.values())))
    p, f = run_host(sq, ["--checksums"], faults={"drop_answer": {1, 5}, "cut_frame": {3}},
                    at_counts=True)
    final_ok(p, f, sqv, "'@' counting itself + lost answers + cut frame")
    p, f = run_host(sq, ["--checksums"], faults={"drop_answer": {2}, "drop_frame": {4}},
                    count_queries=False)
    final_ok(p, f, sqv, "index not counting queries -> detected, recovery by position")
    p, f = run_host(long_job, ["--packets", "--checksums"], cap=64,
                    faults={"drop_packet_answer": {2}})
    final_ok(p, f, lv, "lost packet answer -> settled by position, no vector twice")
    p, f = run_host(sq, ["--checksums"], faults={"restart": {3}})
    lines = [l for l in p.stderr.strip().splitlines() if l]
    check("unit restart mid-job -> non-zero exit, one-line reason, nothing repeated",
          p.returncode != 0 and len(lines) == 1 and "restart" in lines[0]
          and f.executed == sqv[:2], "rc=%s stderr=%r executed=%s" % (p.returncode, p.stderr,
                                                                     f.executed))
    p, f = run_host(sq, [], version="IP999/50 x16 1.1.2000")
    check("wrong unit identity -> refused before any motion",
          p.returncode != 0 and not f.executed and "not a GVE114" in p.stderr, p.stderr)
    p, f = run_host(sq, ["--address", "3"], address=3)
    final_ok(p, f, sqv, "--address 3")

    shutil.rmtree(tmp, ignore_errors=True)
    n = len(RESULTS)
    bad = RESULTS.count(False)
    print("\n%d checks, %d passed, %d failed" % (n, n - bad, bad))
    return 0 if bad == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
