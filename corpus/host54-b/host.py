#!/usr/bin/env python3
"""Host program for the GVE54 CNC motion controller (serial line).

usage: host.py PORT JOBFILE [--baud N] [--address A] [--timeout S] [--tries N]
               [--pause MS] [--angle DEG] [--keep-current] [-v]

Readings of the vendor manual are numbered [R1].. and explained in READINGS.md.
Standard library only.
"""
import argparse
import math
import os
import select
import sys
import termios
import time

DEFAULT_BAUD = 115200          # [R1]
MAXC = 65535                   # per-axis limit of L/C parameters
VMIN, VMAX = 40, 50000         # V range
F_FULL, F_INTCOM, F_RUN, F_INTA = 0x20, 0x10, 0x40, 0x80   # F bits [R18]

ERRTEXT = {0: "OK", 1: "queue full", 2: "command incomplete (watchdog)",
           3: "unknown command", 4: "syntax error", 5: "parameter out of range",
           6: "nothing to GO", 7: "not allowed while running"}


class Fatal(Exception):
    """Stop the job; message is the one-line reason."""


class NoAnswer(Exception):
    pass


def frame(address, cmd, params=()):
    """'!' Adresa Prikaz [parametry] Enter, params separated by ',' [R2]."""
    s = "!" + str(address) + cmd + ",".join(str(p) for p in params) + "\r"
    return s.encode("ascii")


def parse_answer(line):
    """Parse one answer line (without CR). Returns (code, fields) or None when
    the line is damaged. code: low 3 bits error, bit 3 INTA [R3]."""
    if not line:
        return None
    try:
        s = line.decode("ascii")
    except UnicodeDecodeError:
        return None
    if any(ord(c) < 0x20 or ord(c) > 0x7E for c in s):
        return None
    parts = s.split(",")
    head = parts[0]
    if len(head) != 1 or head not in "0123456789ABCDEFabcdef":
        return None
    return int(head, 16), parts[1:]


def baud_const(baud):
    name = "B%d" % baud
    if not hasattr(termios, name):
        raise Fatal("unsupported baud rate %d" % baud)
    return getattr(termios, name)


class Line:
    """Raw 8N1 serial port opened with os.open/termios."""

    def __init__(self, path, baud):
        try:
            self.fd = os.open(path, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
        except OSError as e:
            raise Fatal("cannot open %s: %s" % (path, e.strerror))
        a = termios.tcgetattr(self.fd)
        a[0] = 0                                  # iflag: no translation, no XON/XOFF
        a[1] = 0                                  # oflag: raw output
        a[2] = termios.CS8 | termios.CREAD | termios.CLOCAL   # 8N1 [R1]
        a[3] = 0                                  # lflag: no echo, non-canonical
        sp = baud_const(baud)
        a[4] = a[5] = sp
        a[6][termios.VMIN] = 0
        a[6][termios.VTIME] = 0
        termios.tcsetattr(self.fd, termios.TCSANOW, a)
        self.buf = b""

    def write(self, data):
        while data:
            try:
                n = os.write(self.fd, data)
                data = data[n:]
            except BlockingIOError:
                select.select([], [self.fd], [], 0.1)

    def _fill(self, timeout):
        r, _, _ = select.select([self.fd], [], [], max(0.0, timeout))
        if not r:
            return False
        try:
            chunk = os.read(self.fd, 4096)
        except (BlockingIOError, OSError):
            chunk = b""
        self.buf += chunk
        return bool(chunk)

    def readline(self, timeout):
        """One CR-terminated line (CR stripped, LF ignored) or None on timeout."""
        end = time.monotonic() + timeout
        while b"\r" not in self.buf:
            left = end - time.monotonic()
            if left <= 0:
                return None
            self._fill(left)
        line, _, self.buf = self.buf.partition(b"\r")
        return line.replace(b"\n", b"")

    def drain(self, quiet=0.15, limit=3.0):
        """Discard input until the line has been silent for `quiet` seconds [R9]."""
        end = time.monotonic() + limit
        self.buf = b""
        while time.monotonic() < end:
            if not self._fill(quiet):
                break
        self.buf = b""

    def close(self):
        os.close(self.fd)


class Unit:
    def __init__(self, line, address, timeout, tries, log):
        self.line = line
        self.addr = address
        self.timeout = timeout
        self.tries = tries
        self.log = log
        self.at_step = 0       # how much one '@' advances the index [R5]
        self.counts_refused = False   # refused commands advance the index [R5]
        self.index = None      # last trusted '@' reading, None when stale
        self.stats = {"timeouts": 0, "damaged": 0, "resent": 0, "index_checks": 0}

    # -- one exchange: send a frame, wait for exactly one answer line [R4]
    def exchange(self, cmd, params=(), timeout=None):
        if cmd != "@":
            self.index = None
        self.line.write(frame(self.addr, cmd, params))
        raw = self.line.readline(self.timeout if timeout is None else timeout)
        if raw is None:            # lost frame, lost answer or silence [R22]
            self.stats["timeouts"] += 1
            self.log("  %s%s -> (no answer)" % (cmd, ",".join(map(str, params))))
            self.line.drain()
            raise NoAnswer()
        ans = parse_answer(raw)
        self.log("  %s%s -> %r" % (cmd, ",".join(map(str, params)), raw))
        if ans is None:
            self.stats["damaged"] += 1
            self.line.drain()            # rest of a damaged answer may follow [R9]
        return ans

    # -- idempotent command: repeat until a clean answer [R6]; the REPEAT
    # command '>' is deliberately never used [R16]
    def query(self, cmd, params=(), nfields=0, timeout=None, allow=(0,)):
        last = "no answer"
        for _ in range(self.tries):
            try:
                ans = self.exchange(cmd, params, timeout)
            except NoAnswer:
                last = "no answer"
                continue
            if ans is None:
                last = "damaged answer"
                continue
            code, fields = ans
            err = code & 7
            if err == 2:                 # frame arrived incomplete: send again
                last = "incomplete"
                self.stats["resent"] += 1
                continue
            if err not in allow:
                raise Fatal("unit refused %s%s: error %d (%s)" % (
                    cmd, ",".join(map(str, params)), err, ERRTEXT.get(err, "?")))
            if err == 0 and nfields is not None and len(fields) != nfields:
                last = "wrong answer shape %r" % (fields,)
                self.stats["damaged"] += 1
                self.line.drain()
                continue
            return code, fields
        raise Fatal("no valid answer to %s after %d tries (%s)" % (cmd, self.tries, last))

    def hexbyte(self, s):
        if len(s) not in (1, 2):
            raise ValueError(s)
        return int(s, 16)

    # -- index (@) [R5]
    def read_at(self):
        """One '@' exchange: (value or None, received: True/False/None)."""
        self.stats["index_checks"] += 1
        try:
            ans = self.exchange("@")
        except NoAnswer:
            return None, None            # frame or answer lost: unknown
        if ans is None or (ans[0] & 7) != 0 or len(ans[1]) != 1:
            return None, True            # the unit answered, so it received '@'
        try:
            return self.hexbyte(ans[1][0]), True
        except ValueError:
            return None, True

    def read_index(self):
        """Two consecutive clean '@' answers that agree (b == a + at_step).
        Returns (b, n_received, certain): n_received = '@' frames the unit
        received in this call (counting the last), certain = False when a lost
        '@' makes that count unknown and at_step != 0."""
        prev = None
        n_recv = 0
        certain = True
        for _ in range(self.tries * 2):
            v, got = self.read_at()
            if got is None:
                if self.at_step:
                    certain = False
                prev = None
                continue
            n_recv += 1
            if v is None:
                prev = None
                continue
            if prev is not None and v == (prev + self.at_step) % 256:
                self.index = v
                return v, n_recv, certain
            prev = v
        raise Fatal("cannot read a consistent index (@) from the unit")

    def calibrate_index(self):
        """Find out whether '@' itself advances the index [R5]."""
        vals = []
        for _ in range(self.tries * 2):
            v, got = self.read_at()
            if v is None:
                vals = []
                continue
            vals.append(v)
            if len(vals) >= 3:
                d1 = (vals[-2] - vals[-3]) % 256
                d2 = (vals[-1] - vals[-2]) % 256
                if d1 == d2 and d1 in (0, 1):
                    self.at_step = d1
                    self.index = vals[-1]
                    return d1
        raise Fatal("index (@) answers are inconsistent; cannot verify vectors")

    def calibrate_refused(self):
        """Does a refused command advance the index? Probe with V39, which
        is outside V's range 40..50000 and so changes nothing [R5]."""
        for _ in range(self.tries):
            i0, _, _ = self.read_index()
            try:
                ans = self.exchange("V", [39])
            except NoAnswer:
                continue
            if ans is None or (ans[0] & 7) == 2:
                continue
            if (ans[0] & 7) != 5:
                # not refused as the manual's range says: assume the cautious
                # variant (index proves arrival only) and restore V in setup
                self.log("  V39 not refused (answer %X); cautious index mode" % ans[0])
                return True
            i1, n, certain = self.read_index()
            if not certain:
                continue
            base = (i0 + self.at_step * n) % 256
            if i1 == base:
                return False
            if i1 == (base + 1) % 256:
                return True
        raise Fatal("cannot find out how refused commands are indexed")

    def flags(self):
        code, f = self.query("F", nfields=1)
        try:
            return code, self.hexbyte(f[0])
        except ValueError:
            raise Fatal("bad F answer %r" % (f,))

    def flags_stable(self):
        """Two agreeing F readings (answers carry no checksum) [R9]."""
        last = None
        for _ in range(self.tries):
            cur = self.flags()[1]
            if cur == last:
                return cur
            last = cur
        raise Fatal("F answers do not agree")

    def position(self):
        """PF, always in 1/16 steps [R17]; two agreeing readings [R9]."""
        last = None
        for _ in range(self.tries):
            code, f = self.query("PF", nfields=3)
            try:
                cur = tuple(int(x) for x in f)
            except ValueError:
                self.stats["damaged"] += 1
                continue
            if cur == last:
                return cur
            last = cur
        raise Fatal("PF answers do not agree")


def read_job(path):
    """Returns list of ('V', n) and ('M', (dx,dy,dz), lineno)."""
    out = []
    try:
        text = open(path, encoding="utf-8").read()
    except OSError as e:
        raise Fatal("cannot read job %s: %s" % (path, e.strerror))
    for no, raw in enumerate(text.splitlines(), 1):
        s = raw.split("#", 1)[0].strip()
        if not s:
            continue
        if s.lower().startswith("speed"):
            try:
                v = int(s.split()[1])
            except (IndexError, ValueError):
                raise Fatal("job line %d: bad speed %r" % (no, raw))
            if not VMIN <= v <= VMAX:          # [R21]
                raise Fatal("job line %d: speed %d outside %d..%d" % (no, v, VMIN, VMAX))
            out.append(("V", v, no))
            continue
        try:
            vec = tuple(int(p) for p in s.split(","))
        except ValueError:
            raise Fatal("job line %d: not a vector %r" % (no, raw))
        if len(vec) != 3:
            raise Fatal("job line %d: need dx,dy,dz" % no)
        out.append(("M", vec, no))
    return out


def split_long(vec):
    """Split a vector longer than 65535 on some axis into equal-direction
    pieces whose integer sum is exact [R8]."""
    n = max(1, math.ceil(max(abs(c) for c in vec) / MAXC))
    pieces, done = [], (0, 0, 0)
    for k in range(1, n + 1):
        tgt = tuple(int(round(c * k / n)) for c in vec)
        pieces.append(tuple(t - d for t, d in zip(tgt, done)))
        done = tgt
    return pieces


def angle(a, b):
    na = math.sqrt(sum(c * c for c in a))
    nb = math.sqrt(sum(c * c for c in b))
    if na == 0 or nb == 0:
        return 180.0
    cos = sum(x * y for x, y in zip(a, b)) / (na * nb)
    return math.degrees(math.acos(max(-1.0, min(1.0, cos))))


def plan(job, max_angle):
    """Expand the job to a list of steps: ('V', v) or (kind 'L'/'C', vec, lineno).
    C only when the direction changes by at most max_angle degrees and no
    speed change lies between [R7]."""
    steps, prev = [], None
    for item in job:
        if item[0] == "V":
            steps.append(("V", item[1], item[2]))
            prev = None
            continue
        vec, no = item[1], item[2]
        for piece in split_long(vec):
            kind = "C" if (prev is not None and angle(prev, piece) <= max_angle) else "L"
            steps.append((kind, piece, no))
            prev = piece if any(piece) else None
    return steps


class Host:
    def __init__(self, unit, args, log):
        self.u = unit
        self.a = args
        self.log = log
        self.pos = None          # expected position of all accepted vectors
        self.start = None
        self.sent = 0

    # ---------------------------------------------------------- setup
    def identify(self):
        # '?' version and 'Q' processor id ddmmrrpp [R10]
        code, f = self.u.query("?", nfields=None)
        version = ",".join(f).strip()
        code, f = self.u.query("Q", nfields=1)
        qid = f[0]
        if not (len(qid) == 8 and qid.isdigit() and 1 <= int(qid[0:2]) <= 31
                and 1 <= int(qid[2:4]) <= 12):
            raise Fatal("unit identity answer %r is not a GVE54 processor id" % qid)
        if self.a.expect_id and qid != self.a.expect_id:
            raise Fatal("unit id %s is not the expected %s" % (qid, self.a.expect_id))
        print("unit: version %r, id %s (burnt %s.%s.20%s, #%s)" % (
            version, qid, qid[0:2], qid[2:4], qid[4:6], qid[6:8]))

    def setup(self, first_speed):
        fl = self.u.flags_stable()
        if fl & F_RUN:             # [R20]
            raise Fatal("unit is busy (RUN=1) before the job; not touching it")
        if fl & F_INTA:
            raise Fatal("unit is interrupted (INTA=1, F=%02X); clear it first" % fl)
        d = self.u.calibrate_index()
        self.u.counts_refused = self.u.calibrate_refused()
        self.log("index: '@' advances the index by %d; refused commands %s" % (
            d, "advance it too" if self.u.counts_refused else "do not advance it"))
        # [R11] MF: 1/16 steps and stay there; MU: normal current for motion;
        # T: pause between non-continuing vectors, manual recommends 5..20 ms.
        self.u.query("MU")
        self.u.query("MF")
        self.u.query("T", [self.a.pause])
        self.u.query("V", [first_speed])
        self.start = self.u.position()
        self.pos = list(self.start)
        print("start position %d,%d,%d" % self.start)

    # ---------------------------------------------------------- vectors
    def wait_idle(self, limit):
        end = time.monotonic() + limit
        while time.monotonic() < end:
            fl = self.u.flags_stable()
            if fl & F_INTA:
                self.interrupted(fl)
            if not fl & F_RUN:
                return
            time.sleep(0.02)
        raise Fatal("motion did not end within %.0f s" % limit)

    def interrupted(self, fl):
        # INTA=1: an interrupt stopped the motion; operator decides [R19]
        st = []
        for n in (4, 5):
            try:
                st.append("ST%d=%s" % (n, self.u.query("SR", [n], nfields=1)[1][0]))
            except Fatal:
                pass
        raise Fatal("unit interrupted during job (INTA=1, F=%02X %s)" % (fl, " ".join(st)))

    def settle_by_position(self, vec):
        """Fallback when the index cannot decide: let the queue run empty and
        look where the axes are [R12]."""
        self.log("  index undecided -> checking by position")
        self.u.stats["position_checks"] = self.u.stats.get("position_checks", 0) + 1
        self.wait_idle(self.a.motion_limit)
        p = self.u.position()
        if not any(vec):
            return True
        with_v = tuple(a + b for a, b in zip(self.pos, vec))
        if p == with_v:
            return True
        if p == tuple(self.pos):
            return False
        raise Fatal("position %s is neither %s nor %s: unit restarted or lost steps"
                    % (p, tuple(self.pos), with_v))

    def send_vector(self, kind, vec, lineno):
        """Send one vector so that the unit accepts it exactly once [R5][R6][R12]."""
        backoff = 0.005
        if kind == "L":
            # an L vector is refused (error 1) until the queue before it is
            # done [R7][R13]: wait for RUN=0 instead of hammering the line
            self.wait_idle(self.a.motion_limit)
            # at rest the counter must match what was sent so far; a unit
            # that restarted has a zeroed counter and lost modes [R15]
            p = self.u.position()
            if p != tuple(self.pos):
                raise Fatal("before job line %d the axes are at %d,%d,%d, expected %d,%d,%d "
                            "(unit restarted or lost steps)" % ((lineno,) + p + tuple(self.pos)))
        while True:
            if self.u.index is None:
                i0, _, _ = self.u.read_index()
            else:
                i0 = self.u.index
            hint = None
            try:
                ans = self.u.exchange(kind, list(vec))
                if ans is not None:
                    hint = ans[0]
            except NoAnswer:
                pass
            if hint is not None and (hint & 7) in (3, 4, 5, 7):
                raise Fatal("job line %d: unit refused %s%s: %s" % (
                    lineno, kind, vec, ERRTEXT[hint & 7]))
            if hint is not None and hint & 8:
                self.interrupted(self.u.flags_stable())
            # never trust the single answer: the index decides [R6]
            i1, nrecv, certain = self.u.read_index()
            base = (i0 + self.u.at_step * nrecv) % 256
            if certain and self.u.counts_refused and i1 == (base + 1) % 256:
                # the unit received the frame; only a clean answer tells
                # whether it took the vector or refused it (queue full)
                if hint is not None and (hint & 7) == 0:
                    accepted = True
                elif hint is not None and (hint & 7) == 1:
                    accepted = False
                else:
                    accepted = self.settle_by_position(vec)
                    self.u.index = None
            elif certain and i1 == (base + 1) % 256:
                accepted = True
            elif certain and i1 == base:
                accepted = False
            elif not certain:
                accepted = self.settle_by_position(vec)
                self.u.index = None
            else:
                raise Fatal("job line %d: index jumped %d -> %d (unit restarted?); "
                            "queue and position lost, stopping" % (lineno, i0, i1))
            if hint is not None and (hint & 7) == 0 and not accepted:
                self.log("  answer said OK but index says not accepted")
            if hint is not None and (hint & 7) == 1 and accepted:
                self.log("  answer said full but index says accepted")
            if accepted:
                self.pos = [a + b for a, b in zip(self.pos, vec)]
                self.sent += 1
                return
            if hint is None or (hint & 7) != 1:
                self.u.stats["resent"] += 1
            else:
                time.sleep(backoff)     # queue full / previous path not done [R7]
                backoff = min(0.1, backoff * 2)

    def run(self, steps):
        for s in steps:
            if s[0] == "V":
                self.u.query("V", [s[1]])
                continue
            self.send_vector(s[0], s[1], s[2])
        # end of the job: L0,0,0 is accepted only when the queue before it is
        # done [R13]; it moves nothing, so repeating it is harmless.
        end = time.monotonic() + self.a.motion_limit
        while True:
            code, _ = self.u.query("L", [0, 0, 0], allow=(0, 1))
            if code & 8:
                self.interrupted(self.u.flags_stable())
            if code & 7 == 0:
                break
            if time.monotonic() > end:
                raise Fatal("queue did not finish within %.0f s" % self.a.motion_limit)
            time.sleep(0.02)
        self.wait_idle(self.a.motion_limit)
        final = self.u.position()
        if not self.a.keep_current:
            self.u.query("MD")           # half current when idle [R11]
        return final


def main(argv=None):
    ap = argparse.ArgumentParser(description="Run a job on a GVE54 unit.")
    ap.add_argument("port")
    ap.add_argument("jobfile")
    ap.add_argument("--baud", type=int, default=DEFAULT_BAUD)
    ap.add_argument("--address", default="0", help="unit address (jumpers), default 0 [R2]")
    ap.add_argument("--timeout", type=float, default=0.5, help="answer timeout, s [R4]")
    ap.add_argument("--tries", type=int, default=12, help="attempts per command")
    ap.add_argument("--pause", type=int, default=10, help="T value, ms (5..20 advised)")
    ap.add_argument("--angle", type=float, default=10.0, help="max corner for C vectors, deg")
    ap.add_argument("--motion-limit", type=float, default=3600.0)
    ap.add_argument("--expect-id", default=None, help="required Q answer")
    ap.add_argument("--keep-current", action="store_true", help="do not send MD at the end")
    ap.add_argument("-v", "--verbose", action="store_true")
    a = ap.parse_args(argv)

    def log(msg):
        if a.verbose:
            print(msg, file=sys.stderr)

    if not 1 <= a.pause <= 24:             # [R21]
        print("error: --pause must be 1..24 ms", file=sys.stderr)
        return 2
    line = None
    try:
        job = read_job(a.jobfile)
        steps = plan(job, a.angle)
        # leading speed lines are folded into setup; V1000 is the reset value
        first = 1000
        while steps and steps[0][0] == "V":
            first = steps.pop(0)[1]
        line = Line(a.port, a.baud)
        line.drain(quiet=0.05, limit=0.5)
        unit = Unit(line, a.address, a.timeout, a.tries, log)
        host = Host(unit, a, log)
        host.identify()
        host.setup(first)
        final = host.run(steps)
        want = tuple(host.pos)
        print("final position %d,%d,%d (1/16 steps; expected %d,%d,%d); %d vectors; "
              "line stats %s" % (final + want + (host.sent, unit.stats)))
        if final != want:
            print("error: final position %s differs from the job's %s" % (final, want))
            return 1
        return 0
    except Fatal as e:
        print("error: %s" % e)
        return 1
    except KeyboardInterrupt:
        # stop the machine: HALT answers only after braking [R14]
        try:
            if line is not None:
                line.write(frame(a.address, "H"))
                line.readline(30.0)
        except OSError:
            pass
        print("error: interrupted by user (HALT sent)")
        return 130
    finally:
        if line is not None:
            line.close()


if __name__ == "__main__":
    sys.exit(main())
