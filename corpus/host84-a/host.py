#!/usr/bin/env python3
"""host.py - PC-side driver for the GVE84 hardware interpolator (step/dir, RS232).

Written from the vendor manual (chapter 12, "GVE84 - popis vnitrnich instrukci") only.
See READINGS.md for every place where the manual is silent or ambiguous and what
this program chose to do.

usage: python3 host.py PORT JOBFILE [--baud N] [--address A] [--checksums] [--packets]

Exit codes:
  0  job done, all motion finished, final position verified
  1  communication failure (no valid answer after bounded retries)
  2  usage / job file error
  3  the unit refused a set-up command (error code), or is busy at start
  4  motion interrupted (input / HALT / STOP) and not resumed
  5  motion state lost or unknown (unit restarted, position off the job path, ambiguity)
  130 terminated by SIGINT/SIGTERM (the unit was halted and its queue deleted)
"""

import argparse
import math
import os
import select
import signal
import sys
import termios
import time

EXIT_OK, EXIT_COMM, EXIT_USAGE, EXIT_UNIT, EXIT_INTR, EXIT_STATE, EXIT_SIG = 0, 1, 2, 3, 4, 5, 130

QUEUE_CAP = 64          # 12.5.2 "Jednotka ma buffer na 64 CONT. vektoru" (counted incl. the running one)
VEC_MAX = 2147483647    # 12.5.2 range of one vector component
SPEED_MIN, SPEED_MAX = 10, 100000   # 12.5.3 V / B range

# ST6 / F bits (12.5.11)
F_STOP, F_FREE, F_INTCOM, F_FULL, F_RUN, F_INTA = 0x01, 0x02, 0x10, 0x20, 0x40, 0x80

ERRTEXT = {
    0: "OK", 1: "queue full", 2: "command incomplete (watchdog)", 3: "unknown command",
    4: "syntax error", 5: "parameter out of range", 6: "nothing to GO", 7: "not allowed while running",
}


class GiveUp(Exception):
    def __init__(self, msg, code=EXIT_COMM):
        super().__init__(msg)
        self.code = code


class Terminated(Exception):
    pass


# ---------------------------------------------------------------------------
# framing (12.3.2, 12.5, 12.6)
# ---------------------------------------------------------------------------

def checksum(text):
    """12.3.2: sum of the ASCII values of all characters (incl. the trailing comma) mod 256."""
    return "%02X" % (sum(text.encode("ascii")) & 0xFF)


def frame(addr, body, cs):
    """'!' address command [params] [',' checksum] Enter(CR)."""
    s = "!%d%s" % (addr, body)
    if cs:
        s += ","
        s += checksum(s)
    return (s + "\r").encode("ascii")


class Reply:
    __slots__ = ("code", "params", "raw")

    def __init__(self, code, params, raw):
        self.code, self.params, self.raw = code, params, raw

    @property
    def err(self):
        return self.code & 7

    @property
    def inta(self):
        return bool(self.code & 8)

    def __repr__(self):
        return "Reply(%r)" % self.raw


_HEX = set("0123456789abcdefABCDEF")
_ALPHABET = frozenset(b"0123456789abcdefABCDEF")


def _plain_fields(s):
    fields = s.split(",")
    c = fields[0]
    if len(c) != 1 or c not in _HEX:
        return None
    for p in fields[1:]:
        q = p[1:] if p.startswith("-") else p
        if not q or any(ch not in _HEX for ch in q):
            return None
    return fields


def parse_reply(line, cs, nparams):
    """Return (status, Reply|None). status: ok | bad | badcs | plain | shape.
    With checksums on, the last field must be the checksum of everything up to and
    including the comma before it (12.3.2 example: answer '0,5C')."""
    # line noise in front of an answer (idle-line garbage): skip bytes that cannot start an answer
    k = 0
    while k < len(line) and line[k] not in _ALPHABET:
        k += 1
    line = line[k:]
    if not line:
        return "bad", None
    try:
        s = line.decode("ascii")
    except UnicodeDecodeError:
        return "bad", None
    if any(not (0x20 <= ord(ch) < 0x7F) for ch in s):
        return "bad", None
    body = s
    if cs:
        i = s.rfind(",")
        tail = s[i + 1:] if i >= 0 else ""
        if i < 0 or not 1 <= len(tail) <= 2 or any(ch not in _HEX for ch in tail):
            return ("plain" if _plain_fields(s) is not None else "bad"), None
        if sum(s[:i + 1].encode("ascii")) & 0xFF != int(tail, 16):
            return "badcs", None
        body = s[:i]
    fields = _plain_fields(body)
    if fields is None:
        return "bad", None
    params = fields[1:]
    if nparams is not None and len(params) != nparams:
        return "shape", Reply(int(fields[0], 16), params, s)
    return "ok", Reply(int(fields[0], 16), params, s)


# ---------------------------------------------------------------------------
# serial port
# ---------------------------------------------------------------------------

def open_port(path, baud):
    rate = getattr(termios, "B%d" % baud, None)
    if rate is None:
        raise GiveUp("unsupported baud rate %d" % baud, EXIT_USAGE)
    try:
        fd = os.open(path, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
    except OSError as e:
        raise GiveUp("cannot open %s: %s" % (path, e.strerror), EXIT_COMM)
    try:
        a = termios.tcgetattr(fd)
        a[0] = termios.IGNBRK                                   # iflag: raw, no XON/XOFF, no CR mapping
        a[1] = 0                                                # oflag: raw
        a[2] = termios.CS8 | termios.CREAD | termios.CLOCAL     # 8N1, no HW flow control
        a[3] = 0                                                # lflag: no echo, non-canonical
        a[4] = a[5] = rate
        a[6][termios.VMIN] = 0
        a[6][termios.VTIME] = 0
        termios.tcsetattr(fd, termios.TCSANOW, a)
        termios.tcflush(fd, termios.TCIOFLUSH)
    except termios.error as e:
        os.close(fd)
        raise GiveUp("cannot configure %s: %s" % (path, e), EXIT_COMM)
    return fd


class Link:
    """One command -> one answer (12.3.1, strictly simplex)."""

    def __init__(self, fd, addr, timeout, retries, log):
        self.fd, self.addr, self.timeout, self.retries, self.log = fd, addr, timeout, retries, log
        self.cs = False
        self.buf = bytearray()
        # command index tracking (12.5.12 '@')
        self.idx_ok = False      # calibrated and usable
        self.idx_base = 16       # radix of the '@' answer
        self.idx_self = 0        # 1 if '@' itself advances the index
        self.rej_idx = None      # True/False: commands answered with an error advance the index
        self.idx = None          # index of the last command, if known
        self.plain_streak = 0    # consecutive answers without checksum while checksums are on
        self.detect_restart = False
        self.anchor = None       # last index value known for sure
        self.sent_since = 0      # command lines sent since the anchor

    # -- raw I/O ----------------------------------------------------------
    def _write(self, data):
        deadline = time.monotonic() + max(2.0, self.timeout)
        view = memoryview(data)
        while view:
            left = deadline - time.monotonic()
            if left <= 0:
                raise GiveUp("serial write timed out", EXIT_COMM)
            _, w, _ = select.select([], [self.fd], [], left)
            if not w:
                continue
            try:
                n = os.write(self.fd, view)
            except BlockingIOError:
                continue
            except OSError as e:
                raise GiveUp("serial write failed: %s" % e.strerror, EXIT_COMM)
            view = view[n:]

    def _fill(self, wait):
        r, _, _ = select.select([self.fd], [], [], max(0.0, wait))
        if not r:
            return False
        try:
            data = os.read(self.fd, 4096)
        except BlockingIOError:
            return False
        except OSError as e:
            if e.errno == 5:   # EIO: pty peer closed; treat as silence
                time.sleep(min(wait, 0.05))
                return False
            raise GiveUp("serial read failed: %s" % e.strerror, EXIT_COMM)
        if not data:
            return False
        self.buf += data
        return True

    def readline(self, deadline):
        """Next non-empty line terminated by CR (LF tolerated), or None at the deadline."""
        while True:
            while True:
                cut = -1
                for i, b in enumerate(self.buf):
                    if b in (13, 10):
                        cut = i
                        break
                if cut < 0:
                    break
                line = bytes(self.buf[:cut]).replace(b"\x00", b"")
                del self.buf[:cut + 1]
                if line:
                    return line
            left = deadline - time.monotonic()
            if left <= 0:
                return None
            self._fill(left)

    def discard_input(self, quiet=0.0, maxwait=0.0):
        """Drop everything pending; with quiet>0 also wait (at most maxwait s) until the line
        has been silent for `quiet` s, dropping whatever arrives meanwhile."""
        n = len(self.buf)
        self.buf.clear()
        end = time.monotonic() + maxwait
        while True:
            left = end - time.monotonic()
            wait = min(quiet, left) if left > 0 else 0.0
            got = self._fill(wait)
            n += len(self.buf)
            self.buf.clear()
            if not got or time.monotonic() >= end:
                return n

    def quiet(self):
        """After a lost/damaged answer: let a late answer arrive and throw it away."""
        n = self.discard_input(quiet=max(0.05, 0.25 * self.timeout), maxwait=self.timeout)
        if n:
            self.log(2, "discarded %d late/noise bytes" % n)

    # -- one exchange -------------------------------------------------------
    def exchange(self, body, nparams=0, timeout=None, raw=None):
        """Send one command, read one answer line. Returns (status, Reply|None)."""
        stale = self.discard_input()
        if stale:
            self.log(2, "discarded %d stale bytes before %r" % (stale, body))
        data = raw if raw is not None else frame(self.addr, body, self.cs)
        if self.idx is not None:
            self.anchor, self.sent_since = self.idx, 0
        self.sent_since += max(1, data.count(b"\r"))
        self.log(3, ">> %r" % data)
        self._write(data)
        deadline = time.monotonic() + (timeout or self.timeout)
        line = self.readline(deadline)
        if line is None:
            self.log(2, "no answer to %r" % body)
            self.idx = None
            return "lost", None
        st, rep = parse_reply(line, self.cs, nparams)
        self.log(3, "<< %r (%s)" % (line, st))
        if st == "bad":
            # a line of pure noise may precede the real answer: look briefly for a good line after it
            extra = min(deadline, time.monotonic() + max(0.05, 0.25 * self.timeout))
            while True:
                nxt = self.readline(extra)
                if nxt is None:
                    break
                st2, rep2 = parse_reply(nxt, self.cs, nparams)
                self.log(3, "<< %r (%s)" % (nxt, st2))
                if st2 != "bad":
                    line, st, rep = nxt, st2, rep2
                    break
        if st == "ok":
            self.plain_streak = 0
        elif self.cs and _plain_fields(line.decode("ascii", "replace")) is not None:
            # a well-formed answer without a (valid) checksum
            self.plain_streak += 1
            if self.detect_restart and self.plain_streak >= 4:
                raise GiveUp("answers arrive without checksums although checksums were switched on: the unit "
                             "has most likely restarted (power loss / reset); motion state unknown", EXIT_STATE)
        else:
            self.plain_streak = 0
        if st != "ok":
            self.log(2, "damaged answer %r to %r (%s)" % (line, body, st))
            self.idx = None
            return st, None
        # index bookkeeping
        if raw is not None:
            self.idx = None
        elif body == "@":
            self.idx = self._parse_idx(rep)
            if self.idx is not None and self.anchor is not None and self.detect_restart:
                jump = (self.idx - self.anchor) & 0xFF
                if jump > self.sent_since:
                    raise GiveUp("command index jumped from %d to %d with only %d commands sent: the unit has "
                                 "most likely restarted; motion state unknown" % (self.anchor, self.idx,
                                                                                  self.sent_since), EXIT_STATE)
        elif self.idx is not None:
            if rep.err == 0 or self.rej_idx is True:
                self.idx = (self.idx + 1) & 0xFF
            elif self.rej_idx is None:
                self.idx = None
        return "ok", rep

    def _parse_idx(self, rep):
        if not self.idx_ok or rep.err != 0 or len(rep.params) != 1:
            return None
        try:
            return int(rep.params[0], self.idx_base) & 0xFF
        except ValueError:
            return None

    def cmd(self, body, nparams=0, retries=None, timeout=None, retry_errs=(2, 3, 4)):
        """A repeatable command (A, V, F, PF, @, ... 12.5.12): retry until a valid answer."""
        retries = self.retries if retries is None else retries
        last = None
        for attempt in range(retries + 1):
            if attempt:
                self.quiet()
            st, rep = self.exchange(body, nparams, timeout)
            if st == "ok":
                if rep.err in retry_errs and attempt < retries:
                    self.log(2, "%r answered %d (%s), repeating" % (body, rep.err, ERRTEXT.get(rep.err)))
                    last = rep
                    continue
                return rep
        if last is not None:
            return last
        raise GiveUp("no valid answer to %r after %d attempts" % (body, retries + 1), EXIT_COMM)


# ---------------------------------------------------------------------------
# job file
# ---------------------------------------------------------------------------

def load_job(path):
    items = []   # ('V', n) or ('C', (dx, dy, dz))
    try:
        f = open(path, "r", encoding="utf-8", errors="replace")
    except OSError as e:
        raise GiveUp("cannot read job file %s: %s" % (path, e.strerror), EXIT_USAGE)
    with f:
        for no, line in enumerate(f, 1):
            s = line.split("#", 1)[0].strip()
            if not s:
                continue
            low = s.lower()
            if low.startswith("speed"):
                rest = s[5:].strip().lstrip("=:").strip()
                try:
                    v = int(rest)
                except ValueError:
                    raise GiveUp("%s:%d: bad speed line %r" % (path, no, line.rstrip()), EXIT_USAGE)
                if not SPEED_MIN <= v <= SPEED_MAX:
                    raise GiveUp("%s:%d: speed %d outside %d..%d steps/s (12.5.3)"
                                 % (path, no, v, SPEED_MIN, SPEED_MAX), EXIT_USAGE)
                items.append(("V", v))
                continue
            parts = [p.strip() for p in s.split(",")]
            try:
                if len(parts) != 3:
                    raise ValueError
                vec = tuple(int(p) for p in parts)
            except ValueError:
                raise GiveUp("%s:%d: expected 'dx,dy,dz' or 'speed N', got %r" % (path, no, line.rstrip()),
                             EXIT_USAGE)
            if any(abs(c) > VEC_MAX for c in vec):
                raise GiveUp("%s:%d: component outside +-%d (12.5.2)" % (path, no, VEC_MAX), EXIT_USAGE)
            items.append(("C", vec))
    return items


# ---------------------------------------------------------------------------
# the host
# ---------------------------------------------------------------------------

def _sub(a, b):
    return tuple(x - y for x, y in zip(a, b))


def _add(a, b):
    return tuple(x + y for x, y in zip(a, b))


def _peq(a, b):
    """Position counter compare (32-bit counter may wrap)."""
    return all(((x - y) & 0xFFFFFFFF) == 0 for x, y in zip(a, b))


def _to_s32(v):
    v &= 0xFFFFFFFF
    return v - (1 << 32) if v & 0x80000000 else v


class Host:
    def __init__(self, args, items):
        self.args = args
        self.verbose = args.verbose
        self.vecs = [v for k, v in items if k == "C"]
        self.n = len(self.vecs)
        # speed in effect for each vector
        speed = args.speed
        self.vspeed = []
        for k, v in items:
            if k == "V":
                speed = v
            else:
                self.vspeed.append(speed)
        self.prefix = [(0, 0, 0)]
        for v in self.vecs:
            self.prefix.append(_add(self.prefix[-1], v))
        self.brake = self._plan_brakes()
        self.confirmed = 0      # vectors known to be in the unit (queued or done), in order
        self.done_lo = 0        # vectors known to be finished (lower bound)
        self.base = None        # position counter before the job
        self.cur_V = None
        self.cur_B = None
        self.resumes = 0
        self.run_seen = None    # last time RUN=1 was seen
        self.pending_idle = None
        self.link = None
        self.stop_req = False

    # -- logging ---------------------------------------------------------
    def log(self, level, msg):
        if self.verbose >= level:
            sys.stderr.write("host84: %s\n" % msg)

    # -- planning --------------------------------------------------------
    def _plan_brakes(self):
        """B (12.5.3) per vector: speed to brake to at the end of the vector if another C follows."""
        a = self.args.accel * 1000.0
        delta = self.args.junction_dev
        out = []
        prev_b = None
        nz = [i for i, v in enumerate(self.vecs) if v != (0, 0, 0)]
        nxt = {}
        for j in range(len(nz) - 1):
            nxt[nz[j]] = nz[j + 1]
        for i, v in enumerate(self.vecs):
            vmax = self.vspeed[i]
            if i not in nxt:
                b = prev_b if prev_b is not None else vmax   # end of job / zero vector: keep modal B
            else:
                w = self.vecs[nxt[i]]
                vmax = min(vmax, self.vspeed[nxt[i]])
                lu = math.sqrt(sum(c * c for c in v))
                lw = math.sqrt(sum(c * c for c in w))
                cos_t = -sum(x * y for x, y in zip(v, w)) / (lu * lw)
                if cos_t < -0.999999:
                    vj = float(vmax)
                elif cos_t > 0.999999:
                    vj = SPEED_MIN
                else:
                    s2 = math.sqrt(0.5 * (1.0 - cos_t))
                    vj = math.sqrt(a * delta * s2 / (1.0 - s2)) if s2 < 1 else float(vmax)
                if vj >= vmax:
                    b = vmax
                else:
                    # quantise downwards on a 5 % grid so that smooth curves do not emit a B per vector
                    vj = max(vj, SPEED_MIN)
                    q = SPEED_MIN * (1.05 ** math.floor(math.log(vj / SPEED_MIN) / math.log(1.05)))
                    b = max(SPEED_MIN, min(vmax, int(q)))
            b = max(SPEED_MIN, min(SPEED_MAX, int(b)))
            out.append(b)
            prev_b = b
        return out

    def est_time(self, j0, j1):
        """Generous estimate of the motion time of vectors j0..j1-1 (s)."""
        a = self.args.accel * 1000.0
        t = 0.0
        for i in range(max(0, j0), min(j1, self.n)):
            v = self.vecs[i]
            sp = max(SPEED_MIN, self.vspeed[i])
            L = math.sqrt(sum(c * c for c in v))
            t += L / sp + 2.0 * sp / a + self.args.dwell / 1000.0 + 0.02
        return t

    def wait_budget(self, j0, j1):
        return 2.0 * self.est_time(j0, j1) + self.args.max_wait

    def expected(self, j):
        return _add(self.base, self.prefix[j])

    # -- signals -----------------------------------------------------------
    def check_stop(self):
        if self.stop_req:
            raise Terminated()

    # -- basic queries -----------------------------------------------------
    def read_flags(self):
        rep = self.link.cmd("F", nparams=1)
        if rep.err != 0:
            raise GiveUp("F answered error %d (%s)" % (rep.err, ERRTEXT.get(rep.err)), EXIT_UNIT)
        return int(rep.params[0], 16)

    def read_pos(self):
        rep = self.link.cmd("PF", nparams=3)
        if rep.err != 0:
            raise GiveUp("PF answered error %d (%s)" % (rep.err, ERRTEXT.get(rep.err)), EXIT_UNIT)
        try:
            return tuple(_to_s32(int(p, 10)) for p in rep.params)
        except ValueError:
            raise GiveUp("PF answer %r not decimal" % rep.raw, EXIT_COMM)

    def set_param(self, body, what, optional=False):
        """Modal set-up command (A, V, B, T, $, VK); repeatable."""
        for _ in range(3):
            rep = self.link.cmd(body)
            if rep.err == 0:
                if rep.inta:
                    self.handle_interrupt(self.read_flags())
                return
            if rep.err == 3 and optional:
                self.log(0, "warning: unit does not know %r (%s); continuing with its own setting" % (body, what))
                return
            if rep.err == 7:
                self.log(1, "%s not accepted while running; waiting for idle" % body)
                self.wait_idle_simple()
                continue
            raise GiveUp("unit refused %s (%r): error %d (%s)" % (what, body, rep.err, ERRTEXT.get(rep.err)),
                         EXIT_UNIT)
        raise GiveUp("unit keeps refusing %r" % body, EXIT_UNIT)

    def wait_idle_simple(self):
        deadline = time.monotonic() + self.wait_budget(self.done_lo, self.confirmed)
        while time.monotonic() < deadline:
            self.check_stop()
            if not self.poll_flags() & F_RUN:
                return
            time.sleep(self.args.poll)
        raise GiveUp("unit did not become idle in time", EXIT_STATE)

    # -- state polling -------------------------------------------------------
    def poll_flags(self):
        f = self.read_flags()
        if f & F_INTA:
            f = self.handle_interrupt(f)
        if f & F_RUN:
            self.run_seen = time.monotonic()
            self.pending_idle = None
        return f

    def describe_interrupt(self, f):
        causes = []
        try:
            rep = self.link.cmd("SR4", nparams=1)
            st4 = int(rep.params[0], 16) if rep.err == 0 else None
        except (GiveUp, ValueError):
            st4 = None
        if st4:
            ins = [str(b) for b in range(3) if st4 & (1 << b)]
            causes.append("input INTR%s (ST4=%02X)" % ("/".join(ins) if ins else "?", st4))
        if f & F_INTCOM:
            causes.append("HALT command")
        if f & F_STOP:
            causes.append("stop request")
        return ", ".join(causes) or "unknown cause (ST4=%s)" % ("%02X" % st4 if st4 is not None else "?")

    def handle_interrupt(self, f):
        """INTA=1 (12.5.11): the unit braked because of an input, HALT or STOP."""
        f2 = self.read_flags()       # confirm, the first F answer might have been a stray one
        if not f2 & F_INTA:
            return f2
        cause = self.describe_interrupt(f2)
        unfinished = self.confirmed - self.done_lo
        if self.args.on_interrupt != "resume" or self.resumes >= self.args.max_resumes:
            raise GiveUp("motion interrupted: %s. %d of %d vectors were handed to the unit (up to %d of them may "
                         "still be queued), %d never sent. The unit is left stopped with its queue intact: "
                         "continue with !%dG or clear with !%dD."
                         % (cause, self.confirmed, self.n, unfinished, self.n - self.confirmed,
                            self.args.address, self.args.address), EXIT_INTR)
        self.resumes += 1
        self.log(0, "motion interrupted (%s); resuming (%d/%d)" % (cause, self.resumes, self.args.max_resumes))
        # wait until braking finished: position stable
        deadline = time.monotonic() + self.args.max_wait
        last = None
        while time.monotonic() < deadline:
            p = self.read_pos()
            if p == last:
                break
            last = p
            time.sleep(max(0.05, self.args.poll))
        time.sleep(self.args.resume_delay)
        rep = self.link.cmd("G")
        f3 = self.read_flags()
        if rep.err == 6 and f3 & F_INTA and not f3 & F_RUN:
            # INTA=1 RUN=0: vectors ran out while braking, nothing to GO; clear the flags
            rep = self.link.cmd("D")
            f3 = self.read_flags()
        if f3 & F_INTA:
            raise GiveUp("could not resume after interrupt (%s): INTA still set" % cause, EXIT_INTR)
        return f3

    def idle_check(self):
        """RUN=0 and INTA=0 seen. Verify the position against the job path.
        Returns True if every confirmed vector is finished."""
        p = self.read_pos()
        if _peq(p, self.expected(self.confirmed)):
            self.done_lo = self.confirmed
            self.pending_idle = None
            return True
        for j in range(self.done_lo, self.confirmed):
            if _peq(p, self.expected(j)):
                # idle in front of vector j: not started yet (or queue lost). Tolerate for a while,
                # but first make sure the unit did not restart (its '@' counter would have jumped).
                self.done_lo = j
                if self.link.idx_ok and (self.pending_idle is None or self.pending_idle[0] != j):
                    self.link.cmd("@", nparams=1)
                now = time.monotonic()
                if self.pending_idle is None or self.pending_idle[0] != j:
                    self.pending_idle = (j, now)
                elif now - self.pending_idle[1] > self.args.stall:
                    raise GiveUp("unit idle at %s for %.1fs with %d accepted vectors not executed: the unit lost "
                                 "its queue (restart?)" % (p, now - self.pending_idle[1], self.confirmed - j),
                                 EXIT_STATE)
                return False
        raise GiveUp("unit idle at position %s which is not on the job path (expected %s after %d vectors): "
                     "the unit has restarted or lost steps; motion state unknown"
                     % (p, self.expected(self.confirmed), self.confirmed), EXIT_STATE)

    def progress_update(self):
        """While running: find the earliest outstanding vector the current position lies on."""
        p = self.read_pos()
        for i in range(self.done_lo, self.confirmed):
            a, b = self.expected(i), self.expected(i + 1)
            d = _sub(b, a)
            m = max(range(3), key=lambda k: abs(d[k]))
            if d[m] == 0:
                if _peq(p, a):
                    self.done_lo = i
                    return
                continue
            t = (p[m] - a[m]) / d[m]
            if -1e-9 <= t <= 1 + 1e-9 and all(abs(a[k] + t * d[k] - p[k]) <= 1.01 for k in range(3)):
                self.done_lo = i
                return

    def free_slots(self):
        return QUEUE_CAP - (self.confirmed - self.done_lo)

    # -- set-up ------------------------------------------------------------
    def sync_checksum_mode(self):
        """12.3.2: bring the unit's checksum mode to what was asked, whatever it was before."""
        L = self.link
        want = self.args.checksums
        body = "%+" if want else "%-"
        for attempt in range(L.retries + 1):
            if attempt:
                L.quiet()
            # plain frame, as in the manual ("!0%+"); for "%-" try plain first too
            L.cs = want           # the answer to %+ already carries a checksum, to %- it does not
            st, rep = L.exchange(body, 0, raw=frame(L.addr, body, False))
            if st == "ok" and rep.err == 0:
                return
            if st == "ok" and not want:
                return            # plain answer (even an error): checksums are off now
            # maybe the unit is in the other mode: send the checksummed form
            L.cs = want
            st, rep = L.exchange(body, 0, raw=frame(L.addr, body, True))
            if st == "ok" and rep.err == 0:
                return
        raise GiveUp("no valid answer while switching checksums %s (is the unit connected, right baud rate "
                     "and address?)" % ("on" if want else "off"), EXIT_COMM)

    def calibrate_index(self):
        """12.5.12 '@': learn radix, whether '@' counts itself and whether refused commands count."""
        L = self.link
        for _ in range(3):
            L.quiet()

            def at():
                st, rep = L.exchange("@", 1)
                if st != "ok" or rep.err != 0:
                    raise ValueError
                return rep.params[0]
            try:
                r1 = at()
                r2 = at()
                for _ in range(16):
                    st, rep = L.exchange("F", 1)
                    if st != "ok" or rep.err != 0:
                        raise ValueError
                r3 = at()
                # a command the unit refuses for a documented reason: GO with INTA=0 -> 6 "nothing to GO"
                # (12.5.8: "jen pokud INTA=1, jinak bez efektu"); does a refusal advance the index?
                st, rep = L.exchange("G", 0)
                probe_ok = st == "ok" and rep.err == 6
                L.quiet()
                r4 = at()
            except ValueError:
                continue
            bases = []
            for base in (16, 10):
                try:
                    v = [int(r, base) for r in (r1, r2, r3, r4)]
                except ValueError:
                    continue
                d = (v[1] - v[0]) % 256
                if d in (0, 1) and (v[2] - v[1]) % 256 == 16 + d:
                    bases.append((base, d, v))
            if not bases:
                self.log(1, "'@' answers (%s,%s,%s) do not count commands; index check disabled" % (r1, r2, r3))
                return
            base, d, v = bases[0]
            rej = (v[3] - v[2] - d) % 256
            L.idx_base, L.idx_self, L.idx_ok = base, d, True
            L.rej_idx = {0: False, 1: True}.get(rej) if probe_ok else None
            L.idx = v[3] & 0xFF
            self.log(1, "'@' index: radix %d, counts itself: %s, refused commands counted: %s"
                     % (base, bool(d), L.rej_idx))
            return
        self.log(1, "'@' index calibration failed; index check disabled")

    def setup(self):
        L = self.link
        L.discard_input(quiet=0.05, maxwait=0.3)
        self.sync_checksum_mode()
        L.detect_restart = True
        try:
            rep = L.cmd("?", nparams=None, retries=0)
            self.log(1, "unit version answer: %r" % rep.raw)
        except GiveUp:
            self.log(1, "no answer to version query '?' (ignored)")
        f = self.read_flags()
        if f & (F_RUN | F_INTA):
            if not self.args.clear:
                raise GiveUp("unit is not idle at start (F=%02X: %s%s); refusing to add a job. Use --clear to "
                             "halt it and delete its queue."
                             % (f, "RUN " if f & F_RUN else "", "INTA" if f & F_INTA else ""), EXIT_UNIT)
            if f & F_RUN and not f & F_INTA:
                L.cmd("H", timeout=self.args.halt_timeout, retries=2)
            rep = L.cmd("D")
            f = self.read_flags()
            if f & (F_RUN | F_INTA):
                raise GiveUp("unit still busy after --clear (F=%02X)" % f, EXIT_UNIT)
        self.calibrate_index()
        # modal parameters (12.4 lists the reset values; we set all of them explicitly)
        self.set_param("VK" if self.args.correction else "VN", "velocity correction", optional=True)
        self.set_param("A%d" % self.args.accel, "acceleration")
        self.set_param("T%d" % self.args.dwell, "dwell", optional=True)
        self.set_param("$%d" % self.args.short, "short-vector limit", optional=True)
        first_v = self.vspeed[0] if self.n else self.args.speed
        self.set_param("V%d" % first_v, "speed")
        self.cur_V = first_v
        first_b = self.brake[0] if self.n else first_v
        self.set_param("B%d" % first_b, "brake speed")
        self.cur_B = first_b
        if L.idx_ok:
            L.cmd("@", nparams=1)     # a restart during set-up would show as a jump of the index
        self.base = self.read_pos()
        self.log(1, "start position %s, %d vectors" % (self.base, self.n))

    # -- sending -------------------------------------------------------------
    def apply_modal(self, i):
        if self.cur_V != self.vspeed[i]:
            self.set_param("V%d" % self.vspeed[i], "speed")
            self.cur_V = self.vspeed[i]
        if self.cur_B != self.brake[i]:
            self.set_param("B%d" % self.brake[i], "brake speed")
            self.cur_B = self.brake[i]

    def wait_room(self, need):
        start = time.monotonic()
        deadline = start + self.wait_budget(self.done_lo, self.confirmed)
        while True:
            self.check_stop()
            f = self.poll_flags()
            if not f & F_RUN:
                self.idle_check()
            elif self.args.packets and self.free_slots() < need:
                self.progress_update()
            if not f & F_FULL:
                if not self.args.packets:
                    self.done_lo = max(self.done_lo, self.confirmed - (QUEUE_CAP + 1))
                    return
                if self.free_slots() >= need:
                    return
            if time.monotonic() > deadline:
                raise GiveUp("no room in the unit's queue for %.1fs (queue does not drain)"
                             % (time.monotonic() - start), EXIT_STATE)
            time.sleep(self.args.poll)

    def resolve_by_index(self, idx_before, n_at_attempts=None):
        """'@' after a lost answer to one vector. Returns True (accepted), False (not received) or None."""
        L = self.link
        if not L.idx_ok or idx_before is None:
            return None
        got = None
        attempts = 0
        for attempt in range(L.retries + 1):
            L.quiet()
            attempts += 1
            st, rep = L.exchange("@", 1)
            if st == "ok" and rep.err == 0 and L.idx is not None:
                got = L.idx
                break
        if got is None:
            return None
        possible = set()
        for vr in (0, 1):
            for a in range(1, attempts + 1) if L.idx_self else (0,):
                if (idx_before + vr + a * L.idx_self) & 0xFF == got:
                    possible.add(vr)
        self.log(2, "index before %d, now %d -> received: %s" % (idx_before, got, possible))
        if possible == {0}:
            return False
        if possible == {1} and L.rej_idx is False:
            return True
        return None

    def drain_and_locate(self, lo, hi):
        """Wait until the unit is idle and stable; return j in [lo, hi] with position == expected(j)."""
        start = time.monotonic()
        deadline = start + self.wait_budget(self.done_lo, hi)
        last = None
        since = None
        settle = max(0.2, 3 * self.args.dwell / 1000.0, 2 * self.args.poll)
        while True:
            self.check_stop()
            if time.monotonic() > deadline:
                raise GiveUp("unit did not come to rest within %.1fs while verifying a vector" %
                             (time.monotonic() - start), EXIT_STATE)
            f = self.poll_flags()
            if f & F_RUN:
                last = None
                time.sleep(self.args.poll)
                continue
            p = self.read_pos()
            now = time.monotonic()
            if last is None or not _peq(p, last):
                last, since = p, now
                time.sleep(self.args.poll)
                continue
            if now - since < settle:
                time.sleep(self.args.poll)
                continue
            break
        matches = [j for j in range(lo, hi + 1) if _peq(last, self.expected(j))]
        if not matches:
            raise GiveUp("after an uncertain transfer the unit rests at %s, which matches none of the expected "
                         "positions (%s .. %s): motion state unknown (restart or lost steps)"
                         % (last, self.expected(lo), self.expected(hi)), EXIT_STATE)
        jmin, jmax = min(matches), max(matches)
        if any(self.vecs[t] != (0, 0, 0) for t in range(jmin, jmax)):
            raise GiveUp("cannot tell how many vectors of an uncertain transfer were executed: the path returns "
                         "to the same point (candidates %s)" % matches, EXIT_STATE)
        self.done_lo = jmax
        return jmax

    def send_vector(self, i):
        """Single C command (no packets). Exactly-once: resend only when provably not accepted."""
        L = self.link
        v = self.vecs[i]
        body = "C%d,%d,%d" % v
        failures = 0
        full_since = None
        while True:
            self.check_stop()
            self.wait_room(1)
            if L.idx_ok and L.idx is None:
                try:
                    L.cmd("@", nparams=1)
                except GiveUp:
                    pass
            idx_before = L.idx
            st, rep = L.exchange(body, 0)
            orig_err = rep.err if st == "ok" else None
            if st == "ok" and rep.err != 0 and not L.cs:
                # Without checksums an error answer may be a damaged "0" (12.3.2): a refusal we would
                # repeat could in truth be an accepted vector. F just said the queue has room, so
                # verify before repeating.
                self.log(1, "vector %d: unprotected answer %r, verifying" % (i + 1, rep.raw))
                st = "unverified"
            if st == "ok":
                if rep.err == 0:
                    self.confirmed = i + 1
                    return
                if rep.err == 1:
                    now = time.monotonic()
                    if full_since is None:
                        full_since = now
                    elif now - full_since > self.wait_budget(self.done_lo, self.confirmed):
                        raise GiveUp("unit reports a full queue for %.1fs" % (now - full_since), EXIT_STATE)
                    self.log(2, "vector %d: queue full, will repeat" % (i + 1))
                    time.sleep(self.args.poll)
                    continue
                failures += 1
                if rep.err in (2, 3, 4, 5) and failures <= L.retries:
                    self.log(1, "vector %d refused (%s), repeating" % (i + 1, ERRTEXT.get(rep.err)))
                    L.quiet()
                    continue
                raise GiveUp("vector %d (%s) refused: error %d (%s)" % (i + 1, body, rep.err,
                                                                       ERRTEXT.get(rep.err)), EXIT_UNIT)
            # answer lost or damaged: did the unit take the vector?
            self.log(1, "vector %d: answer %s, verifying" % (i + 1, st))
            verdict = self.resolve_by_index(idx_before)
            if verdict is None:
                self.log(1, "vector %d: index inconclusive, waiting for the unit to stop and checking position"
                         % (i + 1))
                self.confirmed = i
                j = self.drain_and_locate(i, i + 1)
                verdict = (j == i + 1)
            if verdict:
                self.confirmed = i + 1
                return
            if orig_err == 1:
                # a genuine "queue full" (verified not taken): wait and repeat, bounded by time
                now = time.monotonic()
                if full_since is None:
                    full_since = now
                elif now - full_since > self.wait_budget(self.done_lo, self.confirmed):
                    raise GiveUp("unit reports a full queue for %.1fs" % (now - full_since), EXIT_STATE)
                time.sleep(self.args.poll)
                continue
            failures += 1
            if failures > L.retries:
                raise GiveUp("vector %d could not be delivered after %d attempts" % (i + 1, failures), EXIT_COMM)

    def send_packet(self, i, cnt):
        """12.3.3: !A*S, cnt C commands, !A*E<cnt>; one answer 'code,count'."""
        L = self.link
        frames = [frame(L.addr, "*S", L.cs)]
        for k in range(i, i + cnt):
            frames.append(frame(L.addr, "C%d,%d,%d" % self.vecs[k], L.cs))
        frames.append(frame(L.addr, "*E%d" % cnt, L.cs))
        st, rep = L.exchange("*packet", 1, raw=b"".join(frames))
        if st == "ok" and rep.err == 0:
            try:
                got = int(rep.params[0], 10)
            except ValueError:
                got = -1
            if got == cnt:
                self.confirmed = i + cnt
                return cnt
        if st == "ok" and rep.err == 1:
            self.log(1, "packet at vector %d: queue full (%r)" % (i + 1, rep.raw))
        else:
            self.log(1, "packet at vector %d: answer %s %r, verifying by position"
                     % (i + 1, st, rep.raw if rep else None))
        # If the end-of-packet line was lost the unit may still be collecting the packet and would
        # swallow our queries: close any open packet with an empty end marker first.
        L.quiet()
        L.exchange("*E0", None, raw=frame(L.addr, "*E0", L.cs))
        L.quiet()
        self.confirmed = i
        j = self.drain_and_locate(i, i + cnt)
        self.confirmed = j
        return j - i

    def run_job(self):
        failures = 0
        while self.confirmed < self.n:
            self.check_stop()
            i = self.confirmed
            self.apply_modal(i)
            if not self.args.packets:
                self.send_vector(i)
                continue
            cnt = 1
            while (i + cnt < self.n and cnt < self.args.packet_size and self.vspeed[i + cnt] == self.vspeed[i]
                   and self.brake[i + cnt] == self.brake[i]):
                cnt += 1
            self.wait_room(cnt)
            cnt = min(cnt, self.free_slots())
            got = self.send_packet(i, cnt)
            if got == 0:
                failures += 1
                if failures > self.link.retries:
                    raise GiveUp("packet at vector %d could not be delivered after %d attempts"
                                 % (i + 1, failures), EXIT_COMM)
            else:
                failures = 0

    def finish(self):
        """Wait until all motion has finished and the position equals the job's end point."""
        start = time.monotonic()
        deadline = start + self.wait_budget(self.done_lo, self.n)
        settle = max(0.1, 3 * self.args.dwell / 1000.0)
        ok_since = None
        while True:
            self.check_stop()
            f = self.poll_flags()
            now = time.monotonic()
            if not f & F_RUN and self.idle_check():
                if ok_since is None:
                    ok_since = now
                elif now - ok_since >= settle:
                    return
            else:
                ok_since = None
            if now > deadline:
                raise GiveUp("motion did not finish within %.1fs" % (now - start), EXIT_STATE)
            time.sleep(self.args.poll)

    def halt_and_clear(self):
        """On SIGINT/SIGTERM: HALT (answers after braking), then DELETE the rest of the queue."""
        L = self.link
        try:
            L.quiet()
            L.cmd("H", timeout=self.args.halt_timeout, retries=2)
            L.cmd("D", retries=3)
            self.log(0, "unit halted and queue deleted")
        except GiveUp as e:
            self.log(0, "could not halt the unit cleanly: %s" % e)

    def run(self, fd):
        self.link = Link(fd, self.args.address, self.args.timeout, self.args.retries, self.log)
        self.setup()
        self.run_job()
        self.finish()
        self.log(1, "job done: %d vectors, end position %s" % (self.n, self.expected(self.n)))


def build_parser():
    p = argparse.ArgumentParser(description="Run a vector job on a GVE84 interpolator over its serial port.")
    p.add_argument("port")
    p.add_argument("jobfile")
    p.add_argument("--baud", type=int, default=38400, help="line speed (unit is ordered with 38400 or 115200)")
    p.add_argument("--address", type=int, default=0, help="unit address 0..7 (default 0)")
    p.add_argument("--checksums", action="store_true", help="use checksums (12.3.2)")
    p.add_argument("--packets", action="store_true", help="group vectors into packets (12.3.3)")
    p.add_argument("--packet-size", type=int, default=10, help="vectors per packet (1..64, default 10)")
    p.add_argument("--speed", type=int, default=1000, help="V in steps/s before any 'speed' line (default 1000)")
    p.add_argument("--accel", type=int, default=20, help="A in thousands of steps/s^2 (default 20 = reset value)")
    p.add_argument("--dwell", type=int, default=10, help="T in ms between non-continuing vectors, 1..24 (10)")
    p.add_argument("--short", type=int, default=512, help="$ short-vector limit in steps (default 512)")
    p.add_argument("--junction-dev", type=float, default=4.0,
                   help="corner deviation in steps used to compute B at corners (default 4)")
    p.add_argument("--no-correction", dest="correction", action="store_false",
                   help="send VN instead of VK (speed not corrected by direction)")
    p.add_argument("--timeout", type=float, default=1.0, help="answer timeout in s (default 1.0)")
    p.add_argument("--retries", type=int, default=5, help="repeats of a command before giving up (default 5)")
    p.add_argument("--halt-timeout", type=float, default=30.0, help="answer timeout for HALT in s")
    p.add_argument("--max-wait", type=float, default=30.0,
                   help="extra seconds allowed on top of the estimated motion time for any wait (default 30)")
    p.add_argument("--stall", type=float, default=5.0,
                   help="s the unit may sit idle with accepted, unexecuted vectors before we give up")
    p.add_argument("--poll", type=float, default=0.02, help="status poll interval in s")
    p.add_argument("--on-interrupt", choices=("abort", "resume"), default="abort",
                   help="when INTA=1 (input/STOP): abort (default, unit left stopped) or resume with G")
    p.add_argument("--max-resumes", type=int, default=3)
    p.add_argument("--resume-delay", type=float, default=0.5)
    p.add_argument("--clear", action="store_true", help="if the unit is busy at start: HALT and DELETE its queue")
    p.add_argument("-v", "--verbose", action="count", default=0)
    return p


def main(argv=None):
    args = build_parser().parse_args(argv)
    if not 0 <= args.address <= 7:
        sys.stderr.write("host84: address must be 0..7 (12.5)\n")
        return EXIT_USAGE
    if not 1 <= args.dwell <= 24:
        sys.stderr.write("host84: --dwell must be 1..24 ms (12.5.2)\n")
        return EXIT_USAGE
    if not SPEED_MIN <= args.speed <= SPEED_MAX:
        sys.stderr.write("host84: --speed must be %d..%d\n" % (SPEED_MIN, SPEED_MAX))
        return EXIT_USAGE
    if not 1 <= args.packet_size <= QUEUE_CAP:
        sys.stderr.write("host84: --packet-size must be 1..%d\n" % QUEUE_CAP)
        return EXIT_USAGE
    if args.accel < 1 or args.short < 1 or args.timeout <= 0 or args.retries < 0:
        sys.stderr.write("host84: bad numeric option\n")
        return EXIT_USAGE
    try:
        items = load_job(args.jobfile)
    except GiveUp as e:
        sys.stderr.write("host84: %s\n" % e)
        return e.code
    host = Host(args, items)

    def on_signal(signum, _frame):
        host.stop_req = True
        raise Terminated()
    signal.signal(signal.SIGINT, on_signal)
    signal.signal(signal.SIGTERM, on_signal)

    fd = None
    try:
        fd = open_port(args.port, args.baud)
        host.run(fd)
        return EXIT_OK
    except Terminated:
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        signal.signal(signal.SIGTERM, signal.SIG_IGN)
        sys.stderr.write("host84: terminated; halting the unit\n")
        if host.link is not None:
            host.halt_and_clear()
        return EXIT_SIG
    except GiveUp as e:
        sys.stderr.write("host84: error: %s\n" % e)
        return e.code
    finally:
        if fd is not None:
            try:
                os.close(fd)
            except OSError:
                pass


if __name__ == "__main__":
    sys.exit(main())
