#!/usr/bin/env python3
"""host.py - cyclic host for the GVE54 hardware interpolator (firmware Ip54v3).

Usage: python3 host.py PORT JOBFILE [--baud N] [--address A] [options]

Written from the vendor instruction set only ("GVE54 - Instrukcni soubor",
22.12.2007).  Every design choice the document leaves open is listed in
READINGS.md; the numbers [Rnn] in comments refer to that list.

The program is a simple state machine in the spirit of a PLC serial task:
    send ONE frame -> wait for ITS answer (bounded) -> decide -> next frame.
Nothing is ever sent before the previous answer arrived or timed out
("Nelze posilat prikazy bez cekani na odpoved").

Exit codes
    0  job finished, final position verified
    2  bad command line / bad job file (nothing was sent to the unit)
    3  motion stopped by an interrupt input (INTA) and not resumed
    4  communication lost (no valid answer within the link timeout) / no progress
    5  unit refused a command in a way the host cannot recover from
    6  unit restarted (power loss) or lost motion while vectors were pending,
       or final/idle position does not match the job
    130 stopped by the operator (SIGINT/SIGTERM) - unit halted with H
"""
import argparse
import math
import os
import re
import select
import signal
import sys
import termios
import time

# ---------------------------------------------------------------- constants
MAX_STEPS = 65535                 # "v rozsahu -65535 az 65535"
V_MIN, V_MAX = 40, 50000          # "n = 40 az 50000 pulsu/s"
T_MIN, T_MAX = 1, 24              # "n= 1 az 24 milisekund"

# error codes (bits 2..0 of the first answer character) [R6]
E_OK, E_FULL, E_WATCHDOG, E_UNKNOWN, E_SYNTAX, E_RANGE, E_NOGO, E_RUNNING = range(8)
ERR_TEXT = {
    0: "OK", 1: "fronta je plna / vektor neprijat", 2: "prikaz neprisel cely vcas (watch dog)",
    3: "neznamy prikaz", 4: "chyba syntaxe", 5: "parametr mimo meze",
    6: "pro Go neni co spustit", 7: "za chodu vektoru nelze",
}
# ST6 / F bits (bit numbers from the document) [R9]
F_STOP, F_FREE, F_INTCOM, F_FULL, F_RUN, F_INTA = 0x01, 0x02, 0x10, 0x20, 0x40, 0x80

EXIT_OK, EXIT_USAGE, EXIT_INTR, EXIT_LINK, EXIT_UNIT, EXIT_LOST, EXIT_USER = 0, 2, 3, 4, 5, 6, 130


class GiveUp(Exception):
    def __init__(self, code, msg):
        super().__init__(msg)
        self.code = code


def log(verbose, msg):
    if verbose:
        sys.stderr.write("host54: %s\n" % msg)


# ---------------------------------------------------------------- job file
def split_vector(d):
    """Split a vector longer than 65535 steps in any axis into collinear
    pieces with integer components that add up exactly (sent as C) [R15]."""
    m = max(abs(c) for c in d)
    n = max(1, -(-m // MAX_STEPS))
    out, prev = [], (0, 0, 0)
    for i in range(1, n + 1):
        cur = tuple(int(round(c * i / n)) for c in d)  # exact at i == n
        out.append(tuple(a - b for a, b in zip(cur, prev)))
        prev = cur
    return out


def parse_job(path):
    """Returns a list of items: ('speed', n) or ('vec', (dx,dy,dz), lineno)."""
    items = []
    try:
        with open(path, "r", encoding="utf-8", errors="replace") as fh:
            lines = fh.read().splitlines()
    except OSError as e:
        raise GiveUp(EXIT_USAGE, "cannot read job file: %s" % e)
    for no, raw in enumerate(lines, 1):
        line = raw.split("#", 1)[0].strip()          # [R17] '#' starts a comment anywhere
        if not line:
            continue
        m = re.fullmatch(r"(?i)speed\s*[= ]?\s*(\d+)", line)
        if m:
            n = int(m.group(1))
            if not V_MIN <= n <= V_MAX:
                raise GiveUp(EXIT_USAGE, "job line %d: speed %d outside %d..%d" % (no, n, V_MIN, V_MAX))
            items.append(("speed", n))
            continue
        parts = [p.strip() for p in line.split(",")]
        if len(parts) != 3 or not all(re.fullmatch(r"[+-]?\d+", p) for p in parts):
            raise GiveUp(EXIT_USAGE, "job line %d: expected 'dx,dy,dz' or 'speed N', got %r" % (no, raw))
        items.append(("vec", tuple(int(p) for p in parts), no))
    return items


def plan(items, corner_deg):
    """Turn job items into unit commands: ('V', n) or ('L'|'C', vec, lineno).
    A vector is sent as C (continuing) only when it continues the previous
    vector within corner_deg; otherwise as L (start from rest) [R13][R14]."""
    out, prev = [], None
    cos_lim = math.cos(math.radians(corner_deg))
    for it in items:
        if it[0] == "speed":
            out.append(("V", it[1]))
            continue
        _, vec, no = it
        if vec == (0, 0, 0):
            out.append(("L", vec, no))      # [R16] L0,0,0: a normal vector without motion
            prev = None
            continue
        for k, piece in enumerate(split_vector(vec)):
            kind = "L"
            if prev is not None:
                dot = sum(a * b for a, b in zip(prev, piece))
                na = math.sqrt(sum(a * a for a in prev)) * math.sqrt(sum(b * b for b in piece))
                if k > 0 or (na > 0 and dot / na >= cos_lim - 1e-12):
                    kind = "C"
            out.append((kind, piece, no))
            prev = piece
    return out


# ---------------------------------------------------------------- serial link
BAUDS = {n: getattr(termios, "B%d" % n) for n in
         (1200, 2400, 4800, 9600, 19200, 38400, 57600, 115200, 230400) if hasattr(termios, "B%d" % n)}


class Link:
    """Raw 8N1 serial port, no flow control, non-blocking reads with select."""

    def __init__(self, port, baud):
        if baud not in BAUDS:
            raise GiveUp(EXIT_USAGE, "unsupported baud rate %d" % baud)
        try:
            self.fd = os.open(port, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
        except OSError as e:
            raise GiveUp(EXIT_LINK, "cannot open %s: %s" % (port, e))
        try:
            a = termios.tcgetattr(self.fd)
            a[0] = termios.IGNBRK                      # iflag: no CR/LF mapping, no XON/XOFF
            a[1] = 0                                   # oflag: raw
            a[2] = termios.CS8 | termios.CREAD | termios.CLOCAL   # 8 bits, no parity, 1 stop [R2]
            a[3] = 0                                   # lflag: no echo, non-canonical
            a[4] = a[5] = BAUDS[baud]
            a[6][termios.VMIN] = 0
            a[6][termios.VTIME] = 0
            termios.tcsetattr(self.fd, termios.TCSANOW, a)
        except termios.error as e:
            raise GiveUp(EXIT_LINK, "cannot configure %s: %s" % (port, e))
        self.buf = b""
        self.char_time = 10.0 / baud

    def send(self, data):
        end = time.monotonic() + 1.0 + len(data) * self.char_time * 2
        while data:
            try:
                n = os.write(self.fd, data)
                data = data[n:]
            except BlockingIOError:
                if time.monotonic() > end:
                    raise GiveUp(EXIT_LINK, "serial port does not accept data (write blocked)")
                select.select([], [self.fd], [], 0.05)

    def flush_in(self):
        try:
            termios.tcflush(self.fd, termios.TCIFLUSH)
        except termios.error:
            pass
        while self._read_some(0):
            pass
        self.buf = b""

    def _read_some(self, wait):
        r, _, _ = select.select([self.fd], [], [], max(0.0, wait))
        if not r:
            return False
        try:
            chunk = os.read(self.fd, 512)
        except (BlockingIOError, InterruptedError):
            return False
        except OSError:
            time.sleep(min(wait, 0.05))  # pty without peer: behave like a silent line
            return False
        if not chunk:
            time.sleep(min(wait, 0.05))
            return False
        self.buf += chunk
        return True

    def readline(self, deadline):
        """Next CR/LF terminated line (bytes, without terminator) or None at deadline.
        Empty lines are skipped [R5]."""
        while True:
            m = re.search(rb"[\r\n]", self.buf)
            if m:
                line, self.buf = self.buf[:m.start()], self.buf[m.end():]
                if line.strip(b" \x00"):
                    return line
                continue
            left = deadline - time.monotonic()
            if left <= 0:
                return None
            self._read_some(left)

    def drain(self, quiet, maxwait):
        """Swallow late/garbled bytes until the line has been quiet for `quiet` s [R21]."""
        end = time.monotonic() + maxwait
        while time.monotonic() < end:
            if not self._read_some(min(quiet, end - time.monotonic())):
                break
        self.buf = b""


# ---------------------------------------------------------------- answers
ANS_RE = re.compile(r"([0-9A-F])(?:,(.*))?")
SHAPES = {
    "code": re.compile(r""),                                   # vectors, V, A, T, ...
    "byte": re.compile(r"[0-9A-F]{1,2}"),                      # F, SRn, ERn, In
    "index": re.compile(r"[0-9A-F]{1,3}"),                     # @ [R11]
    "pos3": re.compile(r"-?\d+,-?\d+,-?\d+"),                  # PF
    "pos2": re.compile(r"-?\d+,-?\d+"),                        # P
    "any": None,                                               # ?, Q
}


class Answer:
    def __init__(self, code, params):
        self.code = code
        self.err = code & 7
        self.inta = bool(code & 8)
        self.params = params

    def __repr__(self):
        return "Answer(%X,%r)" % (self.code, self.params)


def parse_answer(line, shape):
    """Parse one answer line: 1 hex char [, params] [R4]. None if it does not fit."""
    try:
        s = line.decode("ascii").strip(" \x00")
    except UnicodeDecodeError:
        return None
    if shape == "any":
        return Answer(0, s) if s else None
    m = ANS_RE.fullmatch(s.upper())
    if not m:
        return None
    code, params = int(m.group(1), 16), m.group(2)
    err = code & 7
    if err not in (E_OK,) or shape == "code":
        # error answers and plain commands carry no parameters
        return Answer(code, None) if params is None else None
    rx = SHAPES[shape]
    if rx is None:
        return Answer(code, params)
    if params is None or not rx.fullmatch(params):
        return None
    return Answer(code, params)


def frame(address, body):
    """'!' Adresa Prikaz [parametry] Enter(0Dh) [R3]."""
    return ("!%s%s\r" % (address, body)).encode("ascii")


def index_delta(a, b):
    """Forward distance (mod 256) from index text a to index text b.  The
    document does not say whether @ answers in hex or decimal [R11]: hex is
    assumed; a decimal reading is used only if hex is impossible."""
    def val(s, base):
        try:
            v = int(s, base)
        except ValueError:
            return None
        return v if 0 <= v <= 255 else None
    dh = (val(b, 16) - val(a, 16)) % 256 if val(a, 16) is not None and val(b, 16) is not None else None
    dd = (val(b, 10) - val(a, 10)) % 256 if val(a, 10) is not None and val(b, 10) is not None else None
    return dh, dd


# ---------------------------------------------------------------- unit protocol
class Unit:
    def __init__(self, link, address, timeout, link_timeout, verbose, retries_per_error=5):
        self.link = link
        self.addr = address
        self.timeout = timeout
        self.link_timeout = link_timeout
        self.verbose = verbose
        self.retries_per_error = retries_per_error
        self.trouble = False         # a timeout / garbled answer happened since last health check
        self.troubles = 0            # running count of such events
        self.guard = max(0.5, 3 * timeout)   # quiet time that ends a late answer [R21]
        self.sent = 0                # frames sent (statistics)

    def exchange(self, body, shape, timeout=None):
        """ONE frame, ONE answer: returns Answer, or None if nothing valid came
        in time.  Input is flushed before sending, so only bytes that arrive
        after our frame are considered [R21]."""
        self.link.flush_in()
        self.link.send(frame(self.addr, body))
        self.sent += 1
        deadline = time.monotonic() + (timeout or self.timeout) + 30 * self.link.char_time
        while True:
            line = self.link.readline(deadline)
            if line is None:
                break
            ans = parse_answer(line, shape)
            if ans is not None:
                log(self.verbose > 1, "%-16s -> %r" % (body, line))
                return ans
            log(self.verbose, "%s: ignoring garbled/unexpected answer %r" % (body, line))
            self.trouble = True
            self.troubles += 1
        log(self.verbose, "%s: no valid answer within timeout" % body)
        self.trouble = True
        self.troubles += 1
        self.link.drain(quiet=self.guard, maxwait=self.guard * 4)
        return None

    def query(self, body, shape, timeout=None, ok_errs=(E_OK,)):
        """Send a REPEATABLE command until a valid answer arrives [R19].
        Transmission errors (2,3,4) are retried a bounded number of times;
        any other answer is returned to the caller.  Raises GiveUp when the
        unit stays silent for link_timeout seconds."""
        end = time.monotonic() + self.link_timeout
        terrs = 0
        while True:
            a = self.exchange(body, shape, timeout)
            if a is not None:
                if a.err in (E_WATCHDOG, E_UNKNOWN, E_SYNTAX) and a.err not in ok_errs:
                    terrs += 1
                    self.trouble = True
                    if terrs > self.retries_per_error:
                        raise GiveUp(EXIT_UNIT, "command %s repeatedly refused: %X (%s)"
                                     % (body, a.code, ERR_TEXT[a.err]))
                    continue
                return a
            if time.monotonic() > end:
                raise GiveUp(EXIT_LINK, "no valid answer to %s for %.1f s (wrong port, baud or "
                             "address, cable, or unit without power)" % (body, self.link_timeout))

    def must(self, body, shape="code", ok_errs=(E_OK,)):
        a = self.query(body, shape, ok_errs=ok_errs)
        if a.err not in ok_errs:
            raise GiveUp(EXIT_UNIT, "unit refused %s: %X (%s)" % (body, a.code, ERR_TEXT[a.err]))
        return a

    # convenience readers
    def flags(self):
        a = self.must("F", "byte")
        return int(a.params, 16), a

    def position(self):
        a = self.must("PF", "pos3")
        return tuple(int(v) for v in a.params.split(","))

    def index(self):
        """@ -> index text, or None if the unit refuses @ [R11]."""
        for _ in range(self.retries_per_error):
            a = self.query("@", "index", ok_errs=(E_OK, E_UNKNOWN))
            if a.err == E_OK:
                return a.params
            self.trouble = True
        return None


# ---------------------------------------------------------------- the host
class Host:
    def __init__(self, unit, args, program):
        self.u = unit
        self.a = args
        self.program = program
        self.v = args.verbose
        self.at_self = None            # does @ count itself? None = @ unusable [R12]
        self.origin = (0, 0, 0)
        self.done_sum = [0, 0, 0]      # sum of vectors accepted by the unit
        self.accepted = 0              # unit vectors accepted
        self.accepted_line = 0         # job line of last accepted vector
        self.idle_verified = 0         # self.accepted at the last verified idle state
        self.last_index = None         # last @ answer ...
        self.index_mark = 0            # ... and the unit's frame counter right after it
        self.trouble_seen = 0          # trouble count at the last baseline
        self.resumes = 0
        self.last_pos = None
        self.last_progress = time.monotonic()
        self.last_watch = 0.0
        self.stop_request = False
        self.speed = args.speed

    # -------------------------------------------------------------- helpers
    def info(self, msg):
        log(self.v, msg)

    def expected(self):
        return tuple(o + d for o, d in zip(self.origin, self.done_sum))

    def cmd(self, body, shape="code", ok_errs=(E_OK,)):
        """Repeatable command with INTA awareness."""
        self.check_stop()
        a = self.u.must(body, shape, ok_errs)
        return a

    def check_stop(self):
        if self.stop_request:
            self.halt_and_exit()

    def halt_and_exit(self):
        self.stop_request = False
        msg = "stopped by operator signal"
        try:
            # H answers only after braking - allow a long wait [R24]
            a = self.u.query("H", "code", timeout=self.a.halt_timeout)
            pos = self.u.position()
            msg += "; unit halted (H answered %X) at %s; vectors accepted: %d (job line %d); " \
                   "remaining queue kept in the unit (G continues, D deletes)" % (
                       a.code, pos, self.accepted, self.accepted_line)
        except GiveUp as e:
            msg += "; HALT not confirmed: %s" % e
        raise GiveUp(EXIT_USER, msg)

    def watch(self, what):
        """Progress watchdog for every waiting loop [R23]: give up only if the
        position has not changed for --stall seconds."""
        now = time.monotonic()
        if now - self.last_watch >= 1.0:
            self.last_watch = now
            pos = self.u.position()
            if pos != self.last_pos:
                self.last_pos = pos
                self.last_progress = now
        if now - self.last_progress > self.a.stall:
            raise GiveUp(EXIT_LINK, "no progress for %.0f s while %s (position %s, expected end %s)"
                         % (self.a.stall, what, self.last_pos, self.expected()))

    def progressed(self):
        self.last_progress = time.monotonic()

    def read_index(self):
        i = self.u.index()
        if i is not None:
            self.last_index = i
            self.index_mark = self.u.sent
        return i

    # -------------------------------------------------------------- startup
    def startup(self):
        # 1. establish contact (the unit needs ~2 s after power-up) [R18]
        st, _ = self.u.flags()
        self.info("contact, F=%02X" % st)
        a = self.u.exchange("?", "any")          # informational only, one try
        self.info("version answer: %s" % (a.params if a else "none"))
        self.u.trouble = False
        # 2. calibrate @: does it count itself? [R12]
        i1 = self.u.index()
        i2 = self.u.index() if i1 is not None else None
        if i1 is None or i2 is None:
            self.at_self = None
            sys.stderr.write("host54: warning: index query @ not usable - any lost vector answer "
                             "will stop the job instead of being resolved\n")
        else:
            dh, dd = index_delta(i1, i2)
            d = dh if dh in (0, 1) else dd
            if d not in (0, 1):
                self.at_self = None
                sys.stderr.write("host54: warning: @ answers inconsistent (%s, %s) - not used\n" % (i1, i2))
            else:
                self.at_self = bool(d)
                self.last_index, self.index_mark = i2, self.u.sent
                self.info("@ index %s, counts itself: %s" % (i2, self.at_self))
        # 3. leftover state from a previous run [R20]
        st, _ = self.u.flags()
        self.last_progress = time.monotonic()
        while st & F_RUN and not st & F_INTA:
            self.info("unit still executing earlier motion - waiting")
            self.watch("waiting for earlier motion to finish")
            time.sleep(self.a.poll)
            st, _ = self.u.flags()
        if st & (F_INTA | F_RUN):
            sys.stderr.write("host54: warning: unit was interrupted with a leftover queue "
                             "(F=%02X) - deleting it (D) before the job\n" % st)
            self.cmd("D")
            st, _ = self.u.flags()
            if st & (F_INTA | F_RUN):
                raise GiveUp(EXIT_UNIT, "unit stays interrupted after D (F=%02X)" % st)
        # 4. modal set-up [R7][R8]
        self.setup()
        self.origin = self.u.position()
        self.last_pos = self.origin
        self.idle_verified = 0
        self.info("origin %s" % (self.origin,))

    def setup(self):
        """Idempotent modal set-up; repeated after a restart of the unit."""
        for body in ("MF", "MU", "A%d" % self.a.accel, "V%d" % self.speed,
                     "T%d" % self.a.dwell, "B%d" % self.a.brake, "$%d" % self.a.short):
            a = self.cmd(body, ok_errs=(E_OK,))
            if a.inta:
                self.interrupted("during set-up")

    # -------------------------------------------------------------- interrupts
    def interrupted(self, where):
        """INTA=1: motion was stopped by an interrupt input (or an H) [R25]."""
        st, _ = self.u.flags()
        causes = []
        for n in (4, 5):
            try:
                causes.append("ST%d=%s" % (n, self.u.must("SR%d" % n, "byte").params))
            except GiveUp:
                causes.append("ST%d=?" % n)
        pos = self.u.position()
        what = ("halted by H (INTCOM)" if st & F_INTCOM else "stopped by interrupt input") + \
               " %s; F=%02X %s position %s" % (where, st, " ".join(causes), pos)
        if not st & F_INTA:
            self.info("INTA reported but already clear (F=%02X) - continuing" % st)
            return
        if self.a.on_interrupt != "resume" or self.resumes >= self.a.max_resumes:
            raise GiveUp(EXIT_INTR, "%s; vectors accepted %d (through job line %d); %s; "
                         "send G to finish the queued rest or D to delete it, then restart the "
                         "job after line %d" % (what, self.accepted, self.accepted_line,
                                                "queue still holds vectors" if st & F_RUN else
                                                "queue ran out while braking", self.accepted_line))
        self.resumes += 1
        sys.stderr.write("host54: %s - resuming (%d/%d) in %.1f s\n"
                         % (what, self.resumes, self.a.max_resumes, self.a.resume_delay))
        time.sleep(self.a.resume_delay)
        self.check_stop()
        if st & F_RUN:
            a = self.cmd("G", ok_errs=(E_OK, E_NOGO))   # G is harmless if repeated
        else:
            self.cmd("D")                                # queue already empty: clear flags
        self.progressed()          # an input still active shows up as INTA again on the next F

    # -------------------------------------------------------------- health
    def idle_check(self):
        """Unit reported RUN=0 INTA=0: everything accepted must be finished, so
        the position must equal origin + sum of accepted vectors [R22]."""
        pos = self.u.position()
        if pos == self.expected():
            self.idle_verified = self.accepted
            return True
        return pos

    def status(self):
        """F, followed by a health check whenever anything went wrong on the
        line since the last check (including during this very F) [R26]."""
        st, _ = self.u.flags()
        n = 0
        while self.u.trouble:
            n += 1
            if n > 20:
                raise GiveUp(EXIT_LINK, "line too noisy: health check keeps failing")
            st = self.health_check()
        return st

    def health_check(self):
        """After any lost/garbled answer: detect a restart of the unit [R26]."""
        self.u.trouble = False
        jumped = False
        if self.at_self is not None and self.last_index is not None:
            before, mark = self.last_index, self.index_mark
            i = self.read_index()
            sent = self.u.sent - mark        # every frame since, incl. this @ and its retries
            if i is not None and not self.at_self and self.read_index() != i:
                i = None                     # two @ disagree: no conclusion this time
            if i is not None:
                dh, dd = index_delta(before, i)
                d = dh if dh is not None and dh <= sent + 1 else dd
                jumped = d is None or d > sent + 1
        st, _ = self.u.flags()
        if st & F_INTA:
            return st
        if st & F_RUN:
            if jumped:
                self.info("index moved unexpectedly but unit is running - continuing")
            return st
        pos = self.idle_check()
        t_end = time.monotonic() + 1.0
        while pos is not True and time.monotonic() < t_end:
            time.sleep(0.1)
            st, _ = self.u.flags()
            if st & (F_INTA | F_RUN):
                return st
            pos = self.idle_check()
        if pos is True and not jumped:
            return st
        # unit idle and (index jumped or position differs)
        if pos is True or self.accepted == self.idle_verified:
            sys.stderr.write("host54: warning: unit appears to have restarted while idle "
                             "(nothing was pending) - repeating set-up and continuing\n")
            self.setup()
            if pos is not True:
                self.origin = tuple(p - d for p, d in zip(pos, self.done_sum))
            self.idle_verified = self.accepted
            self.read_index()
            return self.u.flags()[0]
        raise GiveUp(EXIT_LOST, "unit restarted (power loss?) or lost motion: idle at %s but "
                     "expected %s; %d vectors accepted since the last verified idle point "
                     "(job lines after %d may be partly executed); machine position is lost - "
                     "re-reference before continuing" % (
                         pos, self.expected(), self.accepted - self.idle_verified,
                         self.idle_line))

    # -------------------------------------------------------------- vectors
    def send_vector(self, kind, vec, lineno):
        body = "%s%d,%d,%d" % (kind, vec[0], vec[1], vec[2])
        terrs = 0
        self.progressed()
        while True:
            self.check_stop()
            st = self.status()
            if st & F_INTA:
                self.interrupted("before job line %d" % lineno)
                continue
            if kind == "L":
                # L only starts from rest: wait until the queue is finished [R14]
                if st & F_RUN:
                    self.watch("waiting for the queue to finish before job line %d" % lineno)
                    time.sleep(self.a.poll)
                    continue
                r = self.idle_check()
                if r is not True:
                    self.u.trouble = True           # let health_check decide
                    continue
            elif st & F_FULL:
                self.watch("waiting for room in the vector queue")   # [R10]
                time.sleep(self.a.poll)
                continue
            # baseline index just before the vector [R12]
            base = None
            if self.at_self is not None:
                base = self.read_index()
                if base is None:
                    continue
                if not self.at_self:
                    # confirm the baseline: a stray late answer "0,xx" must not become it [R21]
                    if self.read_index() != base:
                        continue
                if self.u.trouble:
                    continue        # the line misbehaved during the baseline: health check first
            self.check_stop()
            a = self.u.exchange(body, "code")
            if a is None:
                a = self.resolve_lost(body, base, lineno)
                if a is None:
                    continue            # proven not received: send again
            if a.err == E_OK:
                self.accepted += 1
                self.accepted_line = lineno
                self.done_sum = [s + v for s, v in zip(self.done_sum, vec)]
                self.progressed()
                if a.inta:
                    self.interrupted("after job line %d" % lineno)
                return
            if a.err in (E_FULL, E_RUNNING):
                self.watch("unit busy (%s) for job line %d" % (ERR_TEXT[a.err], lineno))
                time.sleep(self.a.poll)
                continue
            terrs += 1
            self.u.trouble = True
            if terrs > self.u.retries_per_error:
                raise GiveUp(EXIT_UNIT, "vector %s (job line %d) refused %d times, last %X (%s)"
                             % (body, lineno, terrs, a.code, ERR_TEXT[a.err]))
            self.info("vector %s refused with %X (%s) - not accepted, sending again"
                      % (body, a.code, ERR_TEXT[a.err]))

    def resolve_lost(self, body, base, lineno):
        """The answer to a vector was lost or garbled.  A vector must never be
        simply repeated ("zadavani polohy ne ... musi exaktne dohledat"): ask
        the command index @ and compare with the baseline [R12]."""
        if base is None:
            raise GiveUp(EXIT_UNIT, "answer to %s (job line %d) lost and index @ is not usable - "
                         "cannot tell whether it was accepted; vectors accepted %d (through line %d)"
                         % (body, lineno, self.accepted, self.accepted_line))
        n_v = self.u.sent                # frames sent up to and including the vector
        while True:
            i = self.u.index()
            if i is None:
                raise GiveUp(EXIT_UNIT, "@ refused while resolving %s" % body)
            if self.at_self:
                # k @ frames sent since the vector; the last one certainly counted, the
                # k-1 unanswered ones may or may not have: only the extremes are exact
                k = self.u.sent - n_v
                dh, dd = index_delta(base, i)
                d = dh if dh is not None and 1 <= dh <= k + 1 else dd
                if d == 1 or (k == 1 and d == 2):
                    pass
                elif d == k + 1:
                    d = 2
                elif d is not None and 1 < d <= k:
                    raise GiveUp(EXIT_UNIT, "answer to %s (job line %d) lost and the index cannot be "
                                 "resolved exactly (@ counts itself and an @ answer was lost too); "
                                 "vectors accepted %d (through line %d)"
                                 % (body, lineno, self.accepted, self.accepted_line))
                else:
                    d = None
                want = (1, 2)
            else:
                dh, dd = index_delta(base, i)
                want = (0, 1)
                d = dh if dh in want else (dd if dd in want else None)
            if d is None:
                # index moved by something else: restart or desynchronisation
                self.last_index = None
                self.u.trouble = True
                raise GiveUp(EXIT_LOST, "answer to %s (job line %d) lost and index jumped %s -> %s: "
                             "unit restarted or out of sync; vectors accepted %d (through line %d)"
                             % (body, lineno, base, i, self.accepted, self.accepted_line))
            # confirm with a second @ when @ does not count itself (guards against a stale answer)
            if not self.at_self:
                j = self.u.index()
                if j != i:
                    self.info("@ answers disagree (%s, %s) - asking again" % (i, j))
                    continue
            self.last_index, self.index_mark = i, self.u.sent
            if d == want[0]:
                self.info("%s did not reach the unit - sending again" % body)
                return None
            self.info("%s reached the unit (index %s -> %s) - counted as accepted" % (body, base, i))
            return Answer(0, None)   # flags re-read on the next cycle

    # -------------------------------------------------------------- finish
    def finish(self):
        self.progressed()
        mism_since = None
        while True:
            self.check_stop()
            st = self.status()
            if st & F_INTA:
                self.interrupted("while finishing")
                continue
            if not st & F_RUN:
                r = self.idle_check()
                if r is True:
                    break
                if mism_since is None:
                    mism_since = time.monotonic()
                elif time.monotonic() - mism_since > 2.0:
                    raise GiveUp(EXIT_LOST, "unit idle at %s but job ends at %s - motion lost or "
                                 "duplicated (unit restart?)" % (r, self.expected()))
            else:
                mism_since = None
            self.watch("waiting for the motion to finish")
            time.sleep(self.a.poll)
        if self.a.power_down:
            self.cmd("MD")                       # half current at rest [R8]
        self.info("done: %d unit vectors, final position %s" % (self.accepted, self.expected()))

    # -------------------------------------------------------------- main
    def run(self):
        self.idle_line = 0
        self.startup()
        for item in self.program:
            if item[0] == "V":
                if item[1] != self.speed:
                    self.speed = item[1]
                    a = self.cmd("V%d" % item[1])      # modal, affects following vectors [R27]
                    if a.inta:
                        self.interrupted("at speed change")
                continue
            kind, vec, lineno = item
            if self.accepted == self.idle_verified:
                self.idle_line = self.accepted_line
            self.send_vector(kind, vec, lineno)
        self.finish()


def main(argv=None):
    p = argparse.ArgumentParser(description="Drive a GVE54 interpolator over its serial port.")
    p.add_argument("port")
    p.add_argument("jobfile")
    p.add_argument("--baud", type=int, default=115200, help="default 115200 [R1]")
    p.add_argument("--address", default="0", help="unit address, one character 0-9/A-F (default 0) [R3]")
    p.add_argument("--speed", type=int, default=1000, help="V before the first 'speed' line (default 1000)")
    p.add_argument("--accel", type=int, default=20, help="A, thousands of steps/s2 (default 20)")
    p.add_argument("--dwell", type=int, default=10, help="T, ms between non-continuous vectors (1..24, default 10)")
    p.add_argument("--brake", type=int, default=50000, help="B, speed between C vectors (default 50000)")
    p.add_argument("--short", type=int, default=512, help="$, short-vector limit (default 512)")
    p.add_argument("--corner-deg", type=float, default=10.0,
                   help="max direction change sent as C (continuing) vector (default 10)")
    p.add_argument("--timeout", type=float, default=0.3, help="answer timeout per frame, s")
    p.add_argument("--link-timeout", type=float, default=10.0, help="give up after this long without a valid answer")
    p.add_argument("--halt-timeout", type=float, default=60.0, help="wait for the answer to H")
    p.add_argument("--stall", type=float, default=30.0, help="give up when position does not change for this long")
    p.add_argument("--poll", type=float, default=0.02, help="pause between status polls, s")
    p.add_argument("--on-interrupt", choices=("abort", "resume"), default="abort")
    p.add_argument("--resume-delay", type=float, default=2.0)
    p.add_argument("--max-resumes", type=int, default=3)
    p.add_argument("--no-power-down", dest="power_down", action="store_false",
                   help="do not send MD (half current) after the job")
    p.add_argument("-v", "--verbose", action="count", default=0)
    args = p.parse_args(argv)

    try:
        addr = str(args.address).upper()
        if re.fullmatch(r"1[0-5]", addr):
            addr = "%X" % int(addr)
        if not re.fullmatch(r"[0-9A-F]", addr):
            raise GiveUp(EXIT_USAGE, "address must be one character 0-9 or A-F (or 10..15)")
        for name, val, lo, hi in (("speed", args.speed, V_MIN, V_MAX), ("brake", args.brake, V_MIN, V_MAX),
                                  ("dwell", args.dwell, T_MIN, T_MAX), ("short", args.short, 1, 65535),
                                  ("accel", args.accel, 1, 65535)):
            if not lo <= val <= hi:
                raise GiveUp(EXIT_USAGE, "--%s %d outside %d..%d" % (name, val, lo, hi))
        program = plan(parse_job(args.jobfile), args.corner_deg)
        for item in program:
            if item[0] == "V":
                args.speed = item[1]
            break
        link = Link(args.port, args.baud)
        unit = Unit(link, addr, args.timeout, args.link_timeout, args.verbose)
        host = Host(unit, args, program)

        def on_signal(signum, frm):
            host.stop_request = True
        signal.signal(signal.SIGINT, on_signal)
        signal.signal(signal.SIGTERM, on_signal)
        host.run()
    except GiveUp as e:
        sys.stderr.write("host54: ERROR: %s\n" % e)
        return e.code
    return EXIT_OK


if __name__ == "__main__":
    sys.exit(main())
