#!/usr/bin/env python3
"""GVE114 host: drive a GVE114 hardware interpolator over its serial port.

Written from the vendor manual (chapter 13) alone.  See READINGS.md for every
place where the manual was silent or ambiguous and how this program decides.

usage: python3 host.py PORT JOBFILE [--baud N] [--address A] [--checksums] [--packets]

Exit codes:
  0  job executed completely, motion finished, final position verified
  1  usage / job file / local error
  2  communication failure (no valid answer after bounded retries)
  3  motion stopped by an input interrupt (INTA=1) and not resumed
  4  unit restarted or motion state is unknown (cannot guarantee once-only)
  5  unit refused a command (error code) that retrying cannot fix
  6  timeout: motion did not finish within the computed bound
"""

import argparse
import math
import os
import select
import sys
import termios
import time

EXIT_OK, EXIT_LOCAL, EXIT_COMM, EXIT_INTR, EXIT_STATE, EXIT_REFUSED, EXIT_TIMEOUT = range(7)

BAUDS = {
    9600: termios.B9600, 19200: termios.B19200, 38400: termios.B38400,
    57600: termios.B57600, 115200: termios.B115200,
}
for _n in (230400, 460800, 921600, 500000, 576000, 1000000, 1500000,
           2000000, 3000000, 4000000):
    if hasattr(termios, "B%d" % _n):
        BAUDS[_n] = getattr(termios, "B%d" % _n)

# bits of ST6 / F (13.6.12)
BIT_STOP, BIT_FREE, BIT_INTCOM, BIT_FULL, BIT_RUN, BIT_INTA = 0x01, 0x02, 0x10, 0x20, 0x40, 0x80

ERRTEXT = {
    0: "OK", 1: "queue full / cannot enqueue yet", 2: "command incomplete (watchdog)",
    3: "unknown command", 4: "syntax error", 5: "parameter out of range",
    6: "nothing to GO", 7: "not allowed while running",
}

VMIN, VMAX = 10, 100000
STEPMAX = 2147483647
QUEUE_CAPACITY = 2048          # 13.6.2: buffer for 2048 CONT vectors (1 executing)


class GiveUp(Exception):
    def __init__(self, code, msg):
        super().__init__(msg)
        self.code = code


def log(msg):
    sys.stderr.write("host114: %s\n" % msg)
    sys.stderr.flush()


# --------------------------------------------------------------------------
# framing (13.3.2, 13.6, 13.8)
# --------------------------------------------------------------------------

def checksum(text):
    """13.3.2: sum of ASCII of all characters incl. the appended comma, mod 256."""
    return sum((text + ",").encode("ascii")) % 256


def frame(addr, cmd, cs):
    """One command line: '!' address command [params] Enter (0x0D)."""
    body = "!%d%s" % (addr, cmd)
    if cs:
        body = "%s,%02X" % (body, checksum(body))
    return (body + "\r").encode("ascii")


class Resp:
    __slots__ = ("code", "fields", "raw")

    def __init__(self, code, fields, raw):
        self.code, self.fields, self.raw = code, fields, raw

    @property
    def err(self):          # 3-bit error code (13.8)
        return self.code & 7

    @property
    def inta(self):         # bit 3 of the answer code = INTA
        return bool(self.code & 8)

    def __repr__(self):
        return "Resp(%r)" % self.raw


def clean_line(raw):
    """Keep only printable ASCII (the protocol uses nothing else) and drop
    leading junk that cannot start an answer (an answer starts with a hex digit)."""
    s = "".join(ch for ch in raw.decode("latin-1") if " " <= ch <= "~").strip()
    i = 0
    while i < len(s) and s[i] not in "0123456789ABCDEFabcdef":
        i += 1
    return s[i:]


def parse_answer(line, cs):
    """Parse one answer line. Returns Resp or None if malformed/bad checksum."""
    if not line:
        return None
    if cs:
        pos = line.rfind(",")
        if pos < 0:
            return None
        tail = line[pos + 1:]
        if not (1 <= len(tail) <= 2) or any(c not in "0123456789ABCDEFabcdef" for c in tail):
            return None
        if int(tail, 16) != checksum(line[:pos]):
            return None
        line = line[:pos]
    parts = line.split(",")
    if len(parts[0]) != 1 or parts[0] not in "0123456789ABCDEFabcdef":
        return None
    return Resp(int(parts[0], 16), parts[1:], line)


def looks_checksummed(line):
    return parse_answer(line, True) is not None


# expected answer shapes: number and kind of extra fields after the code
def _is_int(s):
    try:
        int(s, 10)
        return True
    except ValueError:
        return False


def _is_hex(s):
    return 1 <= len(s) <= 2 and all(c in "0123456789ABCDEFabcdef" for c in s)


SHAPES = {
    "none": lambda f: len(f) == 0,
    "any": lambda f: True,
    "hex": lambda f: len(f) == 1 and _is_hex(f[0]),
    "idx": lambda f: len(f) == 1 and f[0].isalnum() and len(f[0]) <= 3,
    "xyz": lambda f: len(f) == 3 and all(_is_int(x) for x in f),
    "count": lambda f: len(f) == 1 and _is_int(f[0]),
    "text": lambda f: len(f) >= 1,
}


# --------------------------------------------------------------------------
# serial port
# --------------------------------------------------------------------------

class Port:
    def __init__(self, path, baud):
        if baud not in BAUDS:
            raise GiveUp(EXIT_LOCAL, "unsupported baud rate %d" % baud)
        self.fd = os.open(path, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
        try:
            attr = termios.tcgetattr(self.fd)
            iflag, oflag, cflag, lflag = attr[0], attr[1], attr[2], attr[3]
            iflag &= ~(termios.IGNBRK | termios.BRKINT | termios.PARMRK | termios.ISTRIP |
                       termios.INLCR | termios.IGNCR | termios.ICRNL | termios.IXON |
                       termios.IXOFF | termios.IXANY | termios.INPCK)
            oflag &= ~termios.OPOST
            lflag &= ~(termios.ECHO | termios.ECHONL | termios.ICANON | termios.ISIG |
                       termios.IEXTEN)
            cflag &= ~(termios.CSIZE | termios.PARENB | termios.CSTOPB)
            if hasattr(termios, "CRTSCTS"):
                cflag &= ~termios.CRTSCTS
            cflag |= termios.CS8 | termios.CREAD | termios.CLOCAL
            attr[0], attr[1], attr[2], attr[3] = iflag, oflag, cflag, lflag
            attr[4] = attr[5] = BAUDS[baud]
            attr[6][termios.VMIN] = 0
            attr[6][termios.VTIME] = 0
            termios.tcsetattr(self.fd, termios.TCSANOW, attr)
        except termios.error as e:
            log("warning: cannot configure port as serial line (%s); continuing raw" % e)
        self.buf = b""
        self.baud = baud

    def write(self, data):
        deadline = time.monotonic() + 5.0
        view = memoryview(data)
        while view:
            try:
                n = os.write(self.fd, view)
                view = view[n:]
            except BlockingIOError:
                if time.monotonic() > deadline:
                    raise GiveUp(EXIT_COMM, "serial write blocked")
                select.select([], [self.fd], [], 0.05)

    def _fill(self, timeout):
        r, _, _ = select.select([self.fd], [], [], max(0.0, timeout))
        if not r:
            return False
        try:
            data = os.read(self.fd, 4096)
        except (BlockingIOError, InterruptedError):
            return False
        except OSError as e:     # pty peer closed etc.
            raise GiveUp(EXIT_COMM, "serial read failed: %s" % e)
        if not data:
            time.sleep(min(timeout, 0.01))
            return False
        self.buf += data
        return True

    def readline(self, deadline):
        """Return the next line (without terminator) or None at the deadline."""
        while True:
            for i, b in enumerate(self.buf):
                if b in (0x0D, 0x0A):
                    line, self.buf = self.buf[:i], self.buf[i + 1:]
                    return line
            if len(self.buf) > 4096:      # runaway noise without terminator
                self.buf = b""
            rest = deadline - time.monotonic()
            if rest <= 0:
                return None
            self._fill(rest)

    def flush_input(self):
        self.buf = b""
        while self._fill(0):
            self.buf = b""

    def drain_quiet(self, quiet=0.05, limit=1.0):
        """Discard input until the line has been quiet for `quiet` s (late answers)."""
        end = time.monotonic() + limit
        self.buf = b""
        while time.monotonic() < end:
            if not self._fill(quiet):
                break
            self.buf = b""
        self.buf = b""


# --------------------------------------------------------------------------
# job file
# --------------------------------------------------------------------------

def parse_job(path, default_speed):
    """Return list of (x, y, z, a, speed, has_a)."""
    try:
        with open(path, "r", encoding="utf-8", errors="replace") as f:
            text = f.read()
    except OSError as e:
        raise GiveUp(EXIT_LOCAL, "cannot read job file: %s" % e)
    return parse_job_text(text, default_speed, path)


def parse_job_text(text, default_speed=1000, path="job"):
    lines = text.splitlines()
    speed = default_speed
    out = []
    for no, line in enumerate(lines, 1):
        s = line.split("#", 1)[0].strip()
        if not s:
            continue
        low = s.lower()
        if low.startswith("speed"):
            arg = s[5:].strip().lstrip("=:").strip()
            try:
                val = float(arg)
            except ValueError:
                raise GiveUp(EXIT_LOCAL, "%s:%d: bad speed line %r" % (path, no, s))
            sp = int(round(val))
            if not VMIN <= sp <= VMAX:
                raise GiveUp(EXIT_LOCAL, "%s:%d: speed %s outside %d..%d pulses/s (13.6.3)"
                             % (path, no, arg, VMIN, VMAX))
            speed = sp
            continue
        parts = [p.strip() for p in s.split(",")]
        if len(parts) not in (3, 4):
            raise GiveUp(EXIT_LOCAL, "%s:%d: expected dx,dy,dz[,da], got %r" % (path, no, s))
        try:
            vals = [int(p, 10) for p in parts]
        except ValueError:
            raise GiveUp(EXIT_LOCAL, "%s:%d: non-integer step count in %r" % (path, no, s))
        for v in vals:
            if abs(v) > STEPMAX:
                raise GiveUp(EXIT_LOCAL, "%s:%d: %d outside +-%d (13.6.2)" % (path, no, v, STEPMAX))
        if len(vals) == 3:
            vals.append(0)
        out.append((vals[0], vals[1], vals[2], vals[3], speed, len(parts) == 4))
    return out


def vec_text(kind, v):
    x, y, z, a = v[0], v[1], v[2], v[3]
    if a == 0:
        return "%s%d,%d,%d" % (kind, x, y, z)
    return "%s%d,%d,%d,%d" % (kind, x, y, z, a)


# --------------------------------------------------------------------------
# the host
# --------------------------------------------------------------------------

class Host:
    def __init__(self, args):
        self.args = args
        self.addr = args.address
        self.port = Port(args.port, args.baud)
        self.cs = False            # checksum mode the unit is (believed to be) in
        self.want_cs = args.checksums
        self.timeout = args.timeout
        self.verbose = args.verbose
        # index (@) bookkeeping, 13.6.13
        self.idx_enabled = False
        self.d_at = self.d_ok = self.d_err = None
        self.idx_radices = {10, 16}
        self.idx_base = None       # raw string of last valid @ answer
        self.rep_trusted = False
        self.d_rep = None
        self.idx_m = 0             # index increments since idx_base (valid answers)
        self.idx_unc = 0           # + up to this many more (commands whose answer was lost)
        # unit modal state as far as we know (None = unknown)
        self.unit_V = None
        self.unit_B = None
        # job / progress
        self.vecs = []
        self.kinds = []
        self.brakes = []
        self.accepted = 0          # number of job vectors known accepted (prefix)
        self.completed_lb = 0      # lower bound of vectors known completed
        self.cum = [(0, 0, 0)]     # cumulative xyz endpoints, relative to p0
        self.p0 = None
        self.deadline = None
        self.after_loss = False
        self.inta_pending = False
        self.resumes = 0
        self.stats = {"sent": 0, "retries": 0, "full": 0, "recoveries": 0}

    # ---------------------------------------------------------------- io
    def dbg(self, msg):
        if self.verbose:
            log(msg)

    def _exchange(self, lines, shape, timeout=None):
        """Send already-framed line(s) once, wait for one answer of `shape`.

        Returns (Resp or None, saw_plain_when_cs) ."""
        self.port.flush_input()
        data = b"".join(lines)
        self.port.write(data)
        self.stats["sent"] += 1
        tx_time = len(data) * 10.0 / self.port.baud
        deadline = time.monotonic() + (timeout or self.timeout) + tx_time
        odd_plain = False
        while True:
            raw = self.port.readline(deadline)
            if raw is None:
                return None, odd_plain
            line = clean_line(raw)
            if not line:
                continue
            r = parse_answer(line, self.cs)
            if r is None:
                if self.cs and len(line) == 1 and parse_answer(line, False) is not None:
                    odd_plain = True      # bare code without checksum: unit lost cs mode?
                self.dbg("  ignored answer %r" % line)
                continue
            ok_shape = SHAPES[shape](r.fields) or (r.err != 0 and len(r.fields) == 0)
            if not ok_shape:
                self.dbg("  answer %r has wrong shape for %s" % (line, shape))
                continue
            self.dbg("  <- %r" % line)
            return r, odd_plain

    def _count_idx(self, r, is_at=False):
        if self.idx_base is None:
            return
        if is_at:
            self.idx_m += self.d_at
        elif r.err == 0:
            self.idx_m += self.d_ok
        else:
            self.idx_m += self.d_err

    def _lost(self):
        """An answer was lost: the command may or may not have been counted."""
        self.idx_unc += 1
        self.after_loss = True

    def set_base(self, s):
        self.idx_base, self.idx_m, self.idx_unc = s, 0, 0

    def loss_drain(self):
        """After a lost/damaged answer: swallow a late answer before going on."""
        self.port.drain_quiet(quiet=self.timeout, limit=3 * self.timeout)
        self.after_loss = False

    def settle(self):
        """Before a non-repeatable command: make sure no late answer of an
        earlier command is still on its way (it would be taken as ours)."""
        if self.after_loss:
            self.port.drain_quiet(quiet=self.timeout, limit=4 * self.timeout)
            self.after_loss = False

    def cmd(self, text, shape="none", retries=None, timeout=None, accept=(0,),
            optional=False):
        """Idempotent command: retried on lost/damaged answers and on error
        codes 2, 3, 4 (transmission damage).  Returns Resp (err in accept or
        other final codes) or None when optional and it never succeeded."""
        retries = self.args.retries if retries is None else retries
        line = frame(self.addr, text, self.cs)
        odd_total = 0
        last = None
        for attempt in range(retries):
            self.dbg("-> %s" % line.decode().strip())
            r, odd = self._exchange([line], shape, timeout)
            odd_total += odd
            if r is None:
                self._lost()
                self.stats["retries"] += 1
                self.loss_drain()
                if odd_total >= 2:
                    self.check_restart("plain answers while checksums are on")
                continue
            self._count_idx(r, is_at=(text == "@"))
            last = r
            if r.inta:
                self.note_inta(r)
            if r.err in accept:
                return r
            if r.err in (2, 3, 4) and attempt + 1 < retries:
                self.stats["retries"] += 1
                self.dbg("  %s -> error %d, repeating" % (text, r.err))
                continue
            if optional:
                return None
            return r
        if optional:
            return None
        if last is not None:
            return last
        self.check_restart("no answer to %s" % text)
        raise GiveUp(EXIT_COMM, "no valid answer to '%s' after %d attempts" % (text, retries))

    def must(self, text, shape="none", **kw):
        r = self.cmd(text, shape, **kw)
        if r is None or r.err != 0:
            code = r.err if r is not None else -1
            raise GiveUp(EXIT_REFUSED, "unit refused '%s': error %d (%s)"
                         % (text, code, ERRTEXT.get(code, "?")))
        return r

    # ------------------------------------------------------ status helpers
    def flags(self):
        r = self.must("F", "hex")
        return int(r.fields[0], 16)

    def position(self):
        r = self.cmd("PF", "xyz", optional=True)
        if r is None or r.err != 0:
            return None
        return tuple(int(v) for v in r.fields)

    def note_inta(self, r):
        self.inta_pending = True

    # ------------------------------------------------------ checksum mode
    def detect_mode(self):
        """Find out whether the unit currently expects checksums (13.3.2).

        Probe with F (harmless status read); an answer that carries a valid
        checksum means checksum mode, a valid plain OK answer means plain mode."""
        for cs in (False, True):
            self.port.flush_input()
            self.port.write(frame(self.addr, "F", cs))
            deadline = time.monotonic() + self.timeout
            while True:
                raw = self.port.readline(deadline)
                if raw is None:
                    break
                line = clean_line(raw)
                rc = parse_answer(line, True)
                if rc is not None and SHAPES["hex"](rc.fields):
                    return True
                rp = parse_answer(line, False)
                if rp is not None and rp.err == 0 and SHAPES["hex"](rp.fields):
                    return False
            self.loss_drain()
        return None

    def check_restart(self, why):
        """Called on persistent trouble: a unit that restarted has checksums off."""
        if not self.cs:
            return
        self.idx_base = None          # the probes below are not counted
        self.after_loss = True
        self.loss_drain()
        mode = self.detect_mode()
        if mode is False:
            raise GiveUp(EXIT_STATE, "unit answers without checksums (%s): it has restarted "
                         "(power loss / reset); motion state unknown" % why)

    def set_cs_mode(self):
        for _ in range(self.args.retries):
            mode = None
            for _ in range(max(3, int(4.0 / self.timeout) + 1)):   # unit may be booting (~2 s)
                mode = self.detect_mode()
                if mode is not None:
                    break
                time.sleep(0.2)
            if mode is None:
                raise GiveUp(EXIT_COMM, "no answer from unit at address %d on %s"
                             % (self.addr, self.args.port))
            self.cs = mode
            if mode == self.want_cs:
                return
            text = "%+" if self.want_cs else "%-"
            line = frame(self.addr, text, self.cs)
            self.port.flush_input()
            self.port.write(line)
            self.port.drain_quiet(quiet=self.timeout / 2, limit=self.timeout)
        raise GiveUp(EXIT_COMM, "cannot switch checksum mode")

    # ------------------------------------------------------ index (@)
    def read_idx(self):
        r = self.cmd("@", "idx", optional=True)
        if r is None or r.err != 0:
            return None
        return r.fields[0]

    def idx_values(self, s):
        out = {}
        for rad in self.idx_radices:
            try:
                v = int(s, rad)
            except ValueError:
                continue
            if 0 <= v <= 255:
                out[rad] = v
        if out and len(out) < len(self.idx_radices) and self.idx_enabled:
            self.idx_radices = set(out)      # e.g. "0C" is not decimal, "200" not hex
        return out

    def idx_diff(self, a, b):
        """{radix: (b-a) mod 256} for radices plausible for both strings."""
        va, vb = self.idx_values(a), self.idx_values(b)
        return {rad: (vb[rad] - va[rad]) % 256 for rad in va if rad in vb}

    def calibrate_index(self):
        """Learn how the unit counts commands for @; redo if answers were lost."""
        for attempt in range(3):
            before = self.stats["retries"]
            self.after_loss = False
            self.idx_note = None
            self._calibrate_index()
            if self.stats["retries"] == before and not self.after_loss:
                if self.idx_note:
                    log("note: %s; lost answers resolved by position only" % self.idx_note)
                return
            self.loss_drain()
        log("note: index calibration disturbed by line errors; recovery uses position only")
        self.idx_enabled = False
        self.rep_trusted = False

    def _calibrate_index(self):
        """Learn how the unit counts commands for @ (13.6.13 is not explicit)."""
        self.idx_enabled = False
        r1 = self.read_idx()
        r2 = self.read_idx()
        if r1 is None or r2 is None:
            self.idx_note = "index command @ unavailable"
            return
        self.must("V%d" % self.unit_V)          # harmless, known good
        r3 = self.read_idx()
        # G with INTA=0 is documented as "bez efektu" -> error 6
        rg = self.cmd("G", accept=(0, 6))
        r4 = self.read_idx()
        if None in (r3, r4) or rg is None or rg.err not in (0, 6):
            self.idx_note = "index calibration inconclusive"
            return
        # the manual does not say whether @ answers in decimal or hex: keep the
        # radices under which the unit behaves consistently
        found = {}
        for rad in sorted(self.idx_radices):
            try:
                v = [int(x, rad) for x in (r1, r2, r3, r4)]
            except ValueError:
                continue
            if any(not 0 <= x <= 255 for x in v):
                continue
            d_at = (v[1] - v[0]) % 256
            d_ok = (v[2] - v[1]) % 256 - d_at
            d_err = (v[3] - v[2]) % 256 - d_at
            if d_at in (0, 1) and d_ok == 1 and d_err in (0, 1):
                found[rad] = (d_at, d_ok, d_err)
        if not found or len(set(found.values())) != 1:
            self.idx_note = "index behaviour not understood"
            return
        self.idx_radices = set(found)
        d_at, d_ok, d_err = next(iter(found.values()))
        self.d_at, self.d_ok, self.d_err = d_at, d_ok, d_err
        self.idx_enabled = True
        self.set_base(r4)
        self.calibrate_repeat(r4)
        self.dbg("index: @ counts itself=%d, errors counted=%d, radices=%s"
                 % (d_at, d_err, sorted(self.idx_radices)))

    def calibrate_repeat(self, r_before):
        """Check that '>' (REPEAT, 13.6.13) only re-sends the last answer.

        Right after an @ answer, '>' must return exactly that answer.  When @
        counts itself, a '>' that re-executed @ would show a new number, so
        '>' is trusted only then.  A following @ tells whether '>' is counted."""
        self.rep_trusted = False
        self.d_rep = None
        if self.d_at != 1:
            self.dbg("REPEAT not used: cannot prove it does not re-execute")
            return
        r, _ = self._exchange([frame(self.addr, ">", self.cs)], "idx")
        if r is None:
            self._lost()
        r5 = self.read_idx()
        self.set_base(r5)
        if r is None or r.err != 0 or r5 is None or r.fields[0] != r_before:
            self.dbg("REPEAT not used (answer %r)" % (r,))
            return
        d = set(self.idx_diff(r_before, r5).values())
        if len(d) != 1:
            return
        d_rep = d.pop() - self.d_at
        if d_rep not in (0, 1):
            return
        self.d_rep = d_rep
        self.rep_trusted = True
        self.dbg("REPEAT trusted, counted in index=%d" % d_rep)

    def confirm_jump(self, s, what):
        """The index answer s fits no expectation.  Read @ once more: if the
        unit continues consistently from s, s was no stale answer -> give up."""
        self.loss_drain()
        r2, _ = self._exchange([frame(self.addr, "@", self.cs)], "idx")
        if r2 is not None and r2.err == 0:
            d2 = self.idx_diff(s, r2.fields[0])
            if d2 and all(d == self.d_at for d in d2.values()):
                self.idx_base = None
                self.check_restart("index jump")
                raise GiveUp(EXIT_STATE, "command index jumped during %s: unit restarted or "
                             "lost commands; motion state unknown" % what)
        self.idx_base = None

    def idx_sync(self):
        if not self.idx_enabled:
            return
        s = self.read_idx()
        if s is not None:
            self.set_base(s)

    def idx_check(self):
        """Continuity check: detects commands the unit lost, or a restart."""
        if not self.idx_enabled:
            return
        if self.idx_base is None:
            self.idx_sync()
            return
        base = self.idx_base
        s = self.read_idx()           # cmd() adds this @ to idx_m / idx_unc
        if s is None or self.idx_base is None:
            return
        lo, span = self.idx_m, self.idx_unc
        diffs = self.idx_diff(base, s)
        if diffs and all((d - lo) % 256 > span for d in diffs.values()):
            self.confirm_jump(s, "check (expected +%d..+%d from %s, unit says %s)"
                              % (lo, lo + span, base, s))
            self.idx_sync()
            return
        self.set_base(s)

    # ------------------------------------------------------ planning
    def plan(self, job):
        """Choose L or C per vector and the brake speed at its end (13.6.2/13.6.3)."""
        n = len(job)
        kinds, brakes = [], []
        lim = math.cos(math.radians(self.args.corner_deg))
        for i, v in enumerate(job):
            zero = not any(v[:4])
            if zero:
                kinds.append("L")           # L0,0,0 is a normal vector (13.6.2)
            elif i == 0 or not any(job[i - 1][:4]):
                kinds.append("C")
            else:
                c = cosang(job[i - 1], v)
                kinds.append("C" if c >= lim and c > 0 else "L")
        for i, v in enumerate(job):
            b = None
            if kinds[i] == "C" and i + 1 < n and kinds[i + 1] == "C":
                c = max(0.0, cosang(v, job[i + 1]))
                b = int(min(v[4], job[i + 1][4]) * c)
                b = max(VMIN, min(VMAX, b))
            brakes.append(b)
        self.kinds, self.brakes = kinds, brakes
        cum = [(0, 0, 0)]
        for v in job:
            x, y, z = cum[-1]
            cum.append((x + v[0], y + v[1], z + v[2]))
        self.cum = cum
        # time bound per vector
        acc = self.args.accel * 1000.0
        t = 0.0
        self.est_cum = [0.0]
        for v in job:
            # rest-to-rest time of a trapezoid/triangle profile over the summed
            # axis lengths (an upper bound for the interpolated move)
            ln = abs(v[0]) + abs(v[1]) + abs(v[2]) + abs(v[3])
            if ln >= v[4] * v[4] / acc:
                t += ln / v[4] + v[4] / acc
            else:
                t += 2.0 * math.sqrt(ln / acc)
            t += self.args.pause / 1000.0
            self.est_cum.append(t)
        self.est_time = t

    # ------------------------------------------------------ setup
    def setup(self, job):
        self.port.flush_input()
        self.set_cs_mode()
        r = self.cmd("?", "any", optional=True)
        if r is not None:
            log("unit version: %s" % ",".join(r.fields))
        r = self.cmd("Q", "any", optional=True)
        if r is not None:
            log("unit id: %s" % ",".join(r.fields))
        f = self.flags()
        if f & BIT_RUN and not f & BIT_INTA:
            raise GiveUp(EXIT_STATE, "unit is already moving (RUN=1, flags %02X); "
                         "refusing to add a job to someone else's motion" % f)
        if f & BIT_INTA:
            log("unit is in an interrupted state (flags %02X): deleting its old queue (D)" % f)
            r = self.cmd("D", accept=(0,))
            if r.err != 0:
                raise GiveUp(EXIT_STATE, "cannot clear old queue: error %d" % r.err)
            f = self.flags()
            if f & (BIT_RUN | BIT_INTA):
                raise GiveUp(EXIT_STATE, "unit still busy/interrupted after D (flags %02X)" % f)
        # modal parameters (13.5, 13.6.2-13.6.5)
        self.must("A%d" % self.args.accel)
        self.must("T%d" % self.args.pause)
        # SHORT: printed as "$n" in both places (13.5, 13.6.2); "S" if the
        # extraction mangled the letter.  Only smoothness depends on it.
        if self.cmd("$%d" % self.args.short, optional=True) is None and \
                self.cmd("S%d" % self.args.short, optional=True) is None:
            log("warning: unit accepted neither $%d nor S%d (short-vector limit left as is)"
                % (self.args.short, self.args.short))
        self.must("VN" if self.args.no_vk else "VK")
        first_speed = job[0][4] if job else self.args.speed
        self.must("V%d" % first_speed)
        self.unit_V = first_speed
        self.cmd("XM100", optional=True)
        self.must("B%d" % VMAX)
        self.unit_B = VMAX
        self.calibrate_index()
        p = self.position()
        if p is None:
            log("warning: PF position query not available; no position verification")
        self.p0 = p
        self.inta_pending = False

    # ------------------------------------------------------ interrupts
    def handle_interrupt(self):
        """INTA=1: motion was stopped by an input (13.6.12) or a HALT."""
        self.inta_pending = False
        f = self.flags()
        self.inta_pending = False
        if not f & BIT_INTA:
            return
        st4 = self.cmd("SR4", "hex", optional=True)
        st5 = self.cmd("SR5", "hex", optional=True)
        pos = self.position()
        cause = "ST4=%s ST5=%s" % (st4.fields[0] if st4 else "?", st5.fields[0] if st5 else "?")
        log("motion interrupted by input: flags %02X %s position %s; %d of %d vectors accepted"
            % (f, cause, pos, self.accepted, len(self.vecs)))
        if self.args.interrupt_wait <= 0:
            raise GiveUp(EXIT_INTR, "stopped by input interrupt (%s). Remaining queue left in the "
                         "unit (send G to continue or D to delete); %d job vectors not sent"
                         % (cause, len(self.vecs) - self.accepted))
        log("waiting up to %.0f s for START (IN6) to resume" % self.args.interrupt_wait)
        end = time.monotonic() + self.args.interrupt_wait
        while time.monotonic() < end:
            r = self.cmd("I1", "hex", optional=True)
            if r is not None and r.err == 0 and not int(r.fields[0], 16) & 0x40:
                f = self.flags()
                if not f & BIT_INTA:
                    return
                if f & BIT_RUN:
                    self.must("G", accept=(0,))
                else:
                    self.must("D")           # queue ran out while braking: clear flags
                f = self.flags()
                self.inta_pending = False
                if not f & BIT_INTA:
                    log("resumed")
                    self.resumes += 1
                    return
            time.sleep(0.1)
        raise GiveUp(EXIT_INTR, "stopped by input interrupt (%s); not resumed in time" % cause)

    def poll_inta(self):
        if self.inta_pending:
            self.handle_interrupt()

    # ------------------------------------------------------ progress / position
    def plausible_lb(self, p):
        """Lower bound of completed vectors from the position (bounding boxes)."""
        if p is None or self.p0 is None:
            return self.completed_lb
        rel = tuple(p[i] - self.p0[i] for i in range(3))
        for j in range(self.completed_lb + 1, self.accepted + 1):
            a, b = self.cum[j - 1], self.cum[j]
            if all(min(a[k], b[k]) - 1 <= rel[k] <= max(a[k], b[k]) + 1 for k in range(3)):
                return j - 1
        if rel == self.cum[self.accepted]:
            return self.accepted
        raise GiveUp(EXIT_STATE, "unit position %s is not on the path sent so far: unit "
                     "restarted or lost steps; motion state unknown" % (p,))

    def motion_bound(self):
        """Generous upper bound for the motion still queued in the unit."""
        t = self.est_cum[self.accepted] - self.est_cum[self.completed_lb]
        return t * self.args.time_factor + self.args.time_margin

    def wait_check(self, w, what):
        """w: [deadline or None, resume count]. Raises when a wait takes too long."""
        now = time.monotonic()
        if w[0] is None or w[1] != self.resumes:
            w[0], w[1] = now + self.motion_bound(), self.resumes
        elif now > w[0]:
            raise GiveUp(EXIT_TIMEOUT, "%s: the unit made no room / did not finish within the "
                         "%.1f s bound computed from the queued motion" % (what, self.motion_bound()))

    def wait_idle(self, what):
        """Poll F until RUN=0 and INTA=0 (bounded)."""
        w = [None, 0]
        while True:
            f = self.flags()
            if f & BIT_INTA:
                self.inta_pending = False
                self.handle_interrupt()
                continue
            if not f & BIT_RUN:
                return
            self.wait_check(w, what)
            time.sleep(self.args.poll)

    def resolve_by_position(self, group, why):
        """Uncertain group of vectors (indices `group`, sent in order): let the
        queue drain, then find how many of them were accepted from PF."""
        self.stats["recoveries"] += 1
        log("uncertain whether vector(s) %d..%d were accepted (%s): draining queue to check "
            "position" % (group[0] + 1, group[-1] + 1, why))
        if self.p0 is None:
            raise GiveUp(EXIT_STATE, "cannot verify vector acceptance without PF (%s)" % why)
        self.wait_idle("recovery")
        p = self.position()
        if p is None:
            raise GiveUp(EXIT_COMM, "no position answer during recovery")
        rel = tuple(p[i] - self.p0[i] for i in range(3))
        base = self.accepted
        matches = [k for k in range(len(group) + 1) if self.cum[base + k] == rel]
        if not matches:
            raise GiveUp(EXIT_STATE, "after recovery the position %s matches no prefix of the "
                         "job: unit restarted or lost steps; motion state unknown" % (p,))
        if len(matches) > 1:
            amb = range(base + matches[0], base + matches[-1])
            if all(not self.vecs[j][3] for j in amb):
                # only vectors without any motion (or xyz-zero with a==0) are ambiguous
                pass
            else:
                raise GiveUp(EXIT_STATE, "cannot tell whether A-axis-only vector(s) %d..%d were "
                             "executed (%s); stopping to avoid running them twice"
                             % (amb[0] + 1, amb[-1] + 1, why))
            k = matches[-1]
        else:
            k = matches[0]
        self.accepted = base + k
        self.completed_lb = self.accepted
        self.unit_B = None
        self.idx_base = None
        self.idx_sync()
        log("recovery: %d of %d uncertain vector(s) had been accepted" % (k, len(group)))
        return k

    # ------------------------------------------------------ sending vectors
    def ensure_modal(self, i):
        v = self.vecs[i]
        if self.unit_V != v[4]:
            self.must("V%d" % v[4])
            self.unit_V = v[4]

    def send_single(self, i):
        """Send vector i alone; returns when it has been accepted exactly once."""
        kind = self.kinds[i]
        v = self.vecs[i]
        text = vec_text(kind, v)
        self.ensure_modal(i)
        if kind == "C" and self.brakes[i] is not None and self.unit_B != self.brakes[i]:
            self.must("B%d" % self.brakes[i])
            self.unit_B = self.brakes[i]
        bad = 0
        w = [None, 0]
        while True:
            self.poll_inta()
            if self.idx_enabled and (self.idx_base is None or self.idx_m > 100
                                     or self.idx_unc > 0):
                self.idx_check()
            self.settle()
            base, m, unc = self.idx_base, self.idx_m, self.idx_unc
            line = frame(self.addr, text, self.cs)
            self.dbg("-> %s" % line.decode().strip())
            r, odd = self._exchange([line], "none")
            if r is None:
                self.after_loss = True
                self.loss_drain()
                k = self.resolve_single(i, base, m, unc)
                if k == 1:
                    if self.inta_pending:
                        self.handle_interrupt()
                    return
                if k == -1:
                    self.wait_check(w, "vector %d (queue full)" % (i + 1))
                    time.sleep(self.args.poll)
                    continue
                bad += 1
                if bad >= self.args.retries:
                    raise GiveUp(EXIT_COMM, "vector %d: no valid answer after %d attempts"
                                 % (i + 1, bad))
                continue
            self._count_idx(r)
            if r.inta:
                self.inta_pending = True
            if r.err == 0:
                self.accepted = i + 1
                if self.inta_pending:
                    self.handle_interrupt()
                return
            if r.err in (1, 7):           # queue full (or L waiting): wait and repeat
                self.stats["full"] += 1
                bad = 0
                if self.inta_pending:
                    self.handle_interrupt()
                    continue
                self.wait_check(w, "vector %d (queue full)" % (i + 1))
                time.sleep(self.args.poll)
                continue
            bad += 1
            self.stats["retries"] += 1
            log("vector %d: error %d (%s), repeating" % (i + 1, r.err, ERRTEXT.get(r.err)))
            if bad >= self.args.retries:
                raise GiveUp(EXIT_REFUSED, "vector %d '%s' refused %d times, last error %d (%s)"
                             % (i + 1, text, bad, r.err, ERRTEXT.get(r.err)))

    def resolve_single(self, i, base, m, unc=0):
        """Answer to vector i lost or damaged.

        Returns 1 if it was accepted, 0 if it was not (must be sent again),
        or -1 if it was refused with error 1 (queue full: wait, then again)."""
        self.stats["recoveries"] += 1
        if self.idx_enabled and base is not None:
            rep = None
            rep_sent = False
            rep_tries = 0
            if self.rep_trusted:
                # REPEAT first: it answers for the last command the unit received
                rep_sent = True
                for _ in range(self.args.retries if self.d_rep == 0 else 1):
                    rep_tries += 1
                    rep, _ = self._exchange([frame(self.addr, ">", self.cs)], "none")
                    if rep is not None:
                        break
                    self.loss_drain()
            s = None
            lost_at = 0
            for _ in range(self.args.retries):
                r, _ = self._exchange([frame(self.addr, "@", self.cs)], "idx")
                if r is not None and r.err == 0:
                    s = r.fields[0]
                    break
                lost_at += 1
                self.loss_drain()
            rep_known = not rep_sent or rep is not None or self.d_rep == 0
            if s is not None and (lost_at == 0 or self.d_at == 0) and rep_known and unc == 0:
                diffs = self.idx_diff(base, s)
                verdicts = set()
                for d in diffs.values():
                    extra = (d - m - self.d_at - (self.d_rep if rep_sent else 0)) % 256
                    verdicts.add(extra if extra in (0, 1) else None)
                self.set_base(s)
                if verdicts == {0}:
                    self.dbg("  index: vector %d did not reach the unit; resending" % (i + 1))
                    return 0
                if verdicts == {1} and self.d_err == 0:
                    self.dbg("  index: vector %d was accepted" % (i + 1))
                    self.accepted = i + 1
                    return 1
                if verdicts == {1} and rep is not None:
                    if rep.inta:
                        self.inta_pending = True
                    self.dbg("  index+repeat: vector %d answered %r" % (i + 1, rep.raw))
                    if rep.err == 0:
                        self.accepted = i + 1
                        return 1
                    return -1 if rep.err in (1, 7) else 0
                if None in verdicts and len(verdicts) == 1:
                    self.confirm_jump(s, "recovery of vector %d (expected +%d or +%d from %s, "
                                      "unit says %s)" % (i + 1, m + self.d_at,
                                                         m + self.d_at + 1, base, s))
                    log("command index inconsistent during recovery of vector %d" % (i + 1))
            elif s is not None:
                # not exact (lost @ / > answers), but a jump outside every possible
                # count still shows a restart
                lo = m + self.d_at + (self.d_rep if rep is not None else 0)
                hi = m + unc + self.d_at * (lost_at + 1) + (self.d_rep or 0) * rep_tries + 1
                diffs = self.idx_diff(base, s)
                if diffs and all((d - lo) % 256 > hi - lo for d in diffs.values()):
                    self.confirm_jump(s, "recovery of vector %d (expected +%d..+%d from %s, "
                                      "unit says %s)" % (i + 1, lo, hi, base, s))
            self.idx_base = None
        k = self.resolve_by_position([i], "lost answer")
        return k

    def send_packet(self, first, count):
        """Send vectors first..first+count-1 (all C) as one packet (13.4)."""
        inner = []
        b = self.unit_B
        for j in range(first, first + count):
            if self.brakes[j] is not None and b != self.brakes[j]:
                inner.append("B%d" % self.brakes[j])
                b = self.brakes[j]
            inner.append(vec_text("C", self.vecs[j]))
        lines = [frame(self.addr, "*S", self.cs)]
        lines += [frame(self.addr, t, self.cs) for t in inner]
        lines.append(frame(self.addr, "*E%d" % len(inner), self.cs))
        self.idx_base = None                  # packet index counting is unknown
        self.poll_inta()
        self.settle()
        self.dbg("-> packet of %d commands (%d vectors)" % (len(inner), count))
        r, _ = self._exchange(lines, "count")
        if r is not None and r.err == 0 and int(r.fields[0]) == len(inner):
            self.accepted = first + count
            self.unit_B = b
            if r.inta:
                self.handle_interrupt()
            return count
        # anything else (lost, damaged, error code, wrong count): the manual does
        # not say what part of the packet was queued -> ask the position
        if r is not None and r.inta:
            self.inta_pending = True
        if r is None:
            self.after_loss = True
            self.loss_drain()
        why = "packet answer %s" % (r.raw if r is not None else "lost")
        if self.inta_pending:
            self.handle_interrupt()
        return self.resolve_by_position(list(range(first, first + count)), why)

    def room(self):
        """Conservative free space in the unit's vector queue."""
        occ = self.accepted - self.completed_lb
        free = QUEUE_CAPACITY - 1 - self.args.queue_margin - occ
        if free < self.args.packet_size:
            self.completed_lb = self.plausible_lb(self.position())
            occ = self.accepted - self.completed_lb
            free = QUEUE_CAPACITY - 1 - self.args.queue_margin - occ
        return free

    # ------------------------------------------------------ job
    def run(self, job):
        self.vecs = job
        self.plan(job)
        self.setup(job)
        self.t_start = time.monotonic()
        n = len(job)
        since_check = 0
        while self.accepted < n:
            i = self.accepted
            self.poll_inta()
            if self.args.packets and self.kinds[i] == "C":
                self.ensure_modal(i)
                cnt = 0
                while (i + cnt < n and cnt < self.args.packet_size and self.kinds[i + cnt] == "C"
                       and job[i + cnt][4] == self.unit_V):
                    cnt += 1
                if cnt >= 2:
                    free = self.room()
                    w = [None, 0]
                    while free < 1:
                        self.wait_check(w, "packet (queue full)")
                        time.sleep(self.args.poll)
                        f = self.flags()
                        if f & BIT_INTA:
                            self.handle_interrupt()
                        free = self.room()
                    cnt = min(cnt, free)
                if cnt >= 2:
                    self.send_packet(i, cnt)
                else:
                    self.send_single(i)
            else:
                self.send_single(i)
            since_check += 1
            if since_check >= self.args.check_every:
                since_check = 0
                if self.idx_enabled and not self.args.packets:
                    self.idx_check()
                if self.p0 is not None:
                    self.completed_lb = self.plausible_lb(self.position())
            if self.verbose and self.accepted % 100 == 0:
                self.dbg("accepted %d/%d" % (self.accepted, n))
        # all vectors handed over: wait for the end of motion (13.6.12 RUN/INTA)
        self.wait_idle("finishing")
        if self.idx_enabled:
            self.idx_check()
        if self.p0 is not None:
            p = self.position()
            exp = tuple(self.p0[k] + self.cum[n][k] for k in range(3))
            if p is None:
                log("warning: could not read final position")
            elif p != exp:
                raise GiveUp(EXIT_STATE, "final position %s differs from expected %s: unit "
                             "restarted or lost steps" % (p, exp))
        f = self.flags()
        if f & (BIT_RUN | BIT_INTA):
            raise GiveUp(EXIT_STATE, "unit not idle at the end (flags %02X)" % f)
        log("job done: %d vectors, %.1f s, %d exchanges, %d retries, %d queue-full waits, "
            "%d recoveries" % (n, time.monotonic() - self.t_start, self.stats["sent"],
                               self.stats["retries"], self.stats["full"],
                               self.stats["recoveries"]))

    def halt(self):
        """Operator abort (Ctrl-C): HALT answers only after braking (13.3.1)."""
        try:
            self.port.drain_quiet(limit=0.2)
            self.port.write(frame(self.addr, "H", self.cs))
            self.port.readline(time.monotonic() + 30.0)
        except Exception:
            pass


def cosang(u, v):
    nu = math.sqrt(sum(c * c for c in u[:4]))
    nv = math.sqrt(sum(c * c for c in v[:4]))
    if nu == 0 or nv == 0:
        return 1.0
    return sum(u[k] * v[k] for k in range(4)) / (nu * nv)


def main(argv=None):
    ap = argparse.ArgumentParser(description="GVE114 host (serial step/dir interpolator)")
    ap.add_argument("port")
    ap.add_argument("jobfile")
    ap.add_argument("--baud", type=int, default=115200, help="default 115200 (13.3 / 10.1)")
    ap.add_argument("--address", type=int, default=0, help="unit address 0-7 (default 0)")
    ap.add_argument("--checksums", action="store_true", help="use checksums (13.3.2)")
    ap.add_argument("--packets", action="store_true", help="packetize C/B commands (13.4)")
    ap.add_argument("--packet-size", type=int, default=10, help="vectors per packet (10)")
    ap.add_argument("--speed", type=int, default=1000, help="V before any 'speed' line (1000)")
    ap.add_argument("--accel", type=int, default=20, help="A in 1000 pulses/s^2 (20)")
    ap.add_argument("--pause", type=int, default=10, help="T ms between L vectors (1-24, 10)")
    ap.add_argument("--short", type=int, default=512, help="$ short vector limit (512)")
    ap.add_argument("--no-vk", action="store_true", help="send VN instead of VK")
    ap.add_argument("--corner-deg", type=float, default=90.0,
                    help="max direction change for a C (continuing) vector (90)")
    ap.add_argument("--timeout", type=float, default=1.0, help="answer timeout s (1.0)")
    ap.add_argument("--retries", type=int, default=6, help="attempts per command (6)")
    ap.add_argument("--poll", type=float, default=0.02, help="poll interval s (0.02)")
    ap.add_argument("--check-every", type=int, default=32,
                    help="vectors between index/position sanity checks (32)")
    ap.add_argument("--queue-margin", type=int, default=16)
    ap.add_argument("--time-factor", type=float, default=3.0)
    ap.add_argument("--time-margin", type=float, default=60.0)
    ap.add_argument("--interrupt-wait", type=float, default=0.0,
                    help="s to wait for START (IN6) after an input stop (0 = give up)")
    ap.add_argument("-v", "--verbose", action="store_true")
    args = ap.parse_args(argv)
    if args.baud == 921000:          # table 10.1 writes 921 000 Bd; the UART rate is 921 600
        args.baud = 921600
    if not 0 <= args.address <= 6:
        log("address must be 0..6 (13.6; address 7 is the spindle output, 13.7)")
        return EXIT_LOCAL
    if not 1 <= args.pause <= 24:
        log("--pause must be 1..24 ms (13.6.2)")
        return EXIT_LOCAL
    if not VMIN <= args.speed <= VMAX:
        log("--speed must be %d..%d" % (VMIN, VMAX))
        return EXIT_LOCAL
    if args.accel < 1 or args.short < 1 or args.packet_size < 1 or args.retries < 1:
        log("bad numeric option")
        return EXIT_LOCAL
    host = None
    try:
        job = parse_job(args.jobfile, args.speed)
        host = Host(args)
        host.run(job)
        return EXIT_OK
    except GiveUp as e:
        log("giving up: %s" % e)
        return e.code
    except KeyboardInterrupt:
        log("interrupted by user: sending HALT")
        if host is not None:
            host.halt()
        return 130
    except OSError as e:
        log("error: %s" % e)
        return EXIT_COMM


if __name__ == "__main__":
    sys.exit(main())
