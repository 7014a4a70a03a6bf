#!/usr/bin/env python3
"""host.py - PC host for the GVE84 interpolator (manual chapter 12).

Usage: host.py PORT JOBFILE [--baud N] [--address A] [--checksums] [--packets]
                 [--packet-size N] [--timeout S] [--corner-deg D] [--dwell MS]

Reading references [Rn] point to READINGS.md.
Standard library only; the port is opened with os.open + termios (raw 8N1).
"""
import argparse
import math
import os
import re
import select
import sys
import termios
import time

QUEUE_SIZE = 64          # "Jednotka má buffer na 64 CONT. vektorů"  [R9]
MAX_VEC = 2147483647     # range of L/C parameters


class Abort(Exception):
    """Job cannot continue safely; message is the one-line reason."""


class LinkDown(Abort):
    pass


class Restarted(Abort):
    """The unit answered like a freshly reset unit [R12]."""


class BadAnswer(Exception):
    pass


def checksum(text):
    # 12.3.2: sum of ASCII of everything incl. '!' and the trailing comma, mod 256,
    # written in hex (two upper-case digits [R4]).
    return "%02X" % (sum(text.encode("ascii")) % 256)


# ---------------------------------------------------------------- serial port
BAUDS = {n: getattr(termios, "B%d" % n) for n in
         (1200, 2400, 4800, 9600, 19200, 38400, 57600, 115200, 230400)
         if hasattr(termios, "B%d" % n)}


def open_port(path, baud):
    fd = os.open(path, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
    try:
        attrs = termios.tcgetattr(fd)
        # raw 8N1 (12.3: "8 bitů, 1 stop bit, bez parity")
        attrs[0] = 0                                   # iflag
        attrs[1] = 0                                   # oflag
        attrs[2] = termios.CS8 | termios.CREAD | termios.CLOCAL  # cflag
        attrs[3] = 0                                   # lflag
        if baud not in BAUDS:
            raise Abort("unsupported baud rate %d" % baud)
        attrs[4] = attrs[5] = BAUDS[baud]
        attrs[6][termios.VMIN] = 0
        attrs[6][termios.VTIME] = 0
        termios.tcsetattr(fd, termios.TCSANOW, attrs)
        termios.tcflush(fd, termios.TCIOFLUSH)
    except termios.error:
        pass  # some pty implementations refuse parts of this; raw is what matters
    return fd


# ---------------------------------------------------------------- link layer
class Answer:
    def __init__(self, code, fields, raw):
        self.code = code          # full hex digit: bit3 INTA, bits 2..0 error code
        self.err = code & 7
        self.inta = bool(code & 8)
        self.fields = fields      # parameters after the code (checksum stripped)
        self.raw = raw

    def __repr__(self):
        return "Answer(%r)" % self.raw


class Unit:
    def __init__(self, fd, address=0, baud=38400, timeout=None, log=None):
        self.fd = fd
        self.addr = str(address)
        self.cs = False            # checksums active on the unit
        self.idx = None            # our idea of the unit's last command index [R6]
        self.at_counts = False     # does '@' count itself? (calibrated) [R6]
        self.repeat_ok = True      # '>' only re-sends, never re-runs (calibrated) [R8]
        self.buf = b""
        # 12.6 "Odpoveď je odeslána ihned" - answer time is line time + USB
        # latency (12.3.3 "1 až 16ms" each way) + margin [R10]
        self.timeout = timeout if timeout else 0.25 + 60 * 10.0 / baud
        self.log = log
        self.stats = {"timeouts": 0, "bad": 0, "resent": 0, "recovered": 0}

    # -- raw io
    def _write(self, data):
        if self.log:
            self.log("> %r" % data)
        while data:
            try:
                n = os.write(self.fd, data)
                data = data[n:]
            except BlockingIOError:
                select.select([], [self.fd], [], 0.05)

    def _readline(self, timeout):
        end = time.monotonic() + timeout
        while True:
            i = self.buf.find(b"\r")
            if i >= 0:
                line, self.buf = self.buf[:i], self.buf[i + 1:]
                line = line.replace(b"\n", b"")  # tolerate CRLF [R5]
                if self.log:
                    self.log("< %r" % line)
                return line
            left = end - time.monotonic()
            if left <= 0:
                return None
            r, _, _ = select.select([self.fd], [], [], left)
            if r:
                try:
                    d = os.read(self.fd, 256)
                except (BlockingIOError, InterruptedError):
                    d = b""
                except OSError as e:
                    raise LinkDown("port read failed: %s" % e)
                self.buf += d

    def drain(self, quiet=0.15, maxwait=1.5):
        """Discard input until the line is quiet (late answers, watchdog '2') [R11]."""
        end = time.monotonic() + maxwait
        last = time.monotonic()
        while time.monotonic() < end and time.monotonic() - last < quiet:
            r, _, _ = select.select([self.fd], [], [], quiet / 3)
            if r:
                try:
                    d = os.read(self.fd, 256)
                except (BlockingIOError, InterruptedError):
                    d = b""
                if d:
                    last = time.monotonic()
                    if self.log:
                        self.log("< (drained) %r" % d)
        self.buf = b""

    def frame(self, body, cs=None):
        cs = self.cs if cs is None else cs
        text = "!" + self.addr + body
        if cs:
            text += "," + checksum(text + ",")
        return text + "\r"

    def parse(self, line, cs=None):
        cs = self.cs if cs is None else cs
        try:
            s = line.decode("ascii")
        except UnicodeDecodeError:
            raise BadAnswer("non-ascii answer %r" % line)
        if cs:
            k = s.rfind(",")
            if k < 0 or not re.fullmatch(r"[0-9A-Fa-f]{1,2}", s[k + 1:]):
                raise BadAnswer("answer without checksum %r" % s)
            if int(s[k + 1:], 16) != sum(s[:k + 1].encode()) % 256:
                raise BadAnswer("answer checksum mismatch %r" % s)
            s = s[:k]
        parts = s.split(",")
        if not re.fullmatch(r"[0-9A-Fa-f]", parts[0]):
            raise BadAnswer("answer does not start with a status digit %r" % s)
        return Answer(int(parts[0], 16), parts[1:], s)

    def once(self, body, cs=None, timeout=None):
        """Send one frame, return a parsed Answer, or None on timeout/damage."""
        self._write(self.frame(body, cs).encode("ascii"))
        line = self._readline(timeout or self.timeout)
        if line is None:
            self.stats["timeouts"] += 1
            return None
        try:
            return self.parse(line, cs)
        except BadAnswer:
            self.stats["bad"] += 1
            return None

    # -- recovery primitives (12.5.12)
    def query_index(self, tries=6):
        """'@' - index of the last command. Read as hex [R7]. Side-effect free."""
        for _ in range(tries):
            a = self.once("@")
            if a is not None and a.err == 0 and a.fields:
                try:
                    v = int(a.fields[0], 16) % 256
                except ValueError:
                    v = None
                if v is not None:
                    return v
            self.drain()
        self.check_restart()
        raise LinkDown("no valid answer to index query '@'")

    def repeat(self, tries=6):
        """'>' - the unit re-sends its answer to the last received command [R8]."""
        for _ in range(tries):
            self._write(self.frame(">").encode("ascii"))
            line = self._readline(self.timeout)
            if line is not None and line.startswith(b"!"):
                # tolerate an echo of the command text before the answer [R8]
                echo = line
                line = self._readline(self.timeout)
            else:
                echo = None
            if line is not None:
                try:
                    return self.parse(line), echo
                except BadAnswer:
                    self.stats["bad"] += 1
            self.drain()
        self.check_restart()
        raise LinkDown("no valid answer to repeat '>'")

    def check_restart(self):
        """Probe with a plain PF. A reset unit has checksums off (12.3.2
        'Po zapnutí napájení/resetu jsou kontrolní součty vypnuté') [R12]."""
        if not self.cs:
            return
        time.sleep(0.1)
        self.drain()
        a = self.once("PF", cs=False, timeout=max(self.timeout, 2.5))
        if a is not None and a.err == 0 and len(a.fields) == 3:
            raise Restarted("unit restarted (answers without checksums)")

    # -- the normal transaction
    def command(self, body, tries=8, repeatable=True):
        """Send a command and return its answer exactly once.

        A lost/damaged answer is resolved with '@' (was it received?) and '>'
        (what was the answer?); the command is re-sent only when the unit did
        not receive it [R6][R8]. Returns an Answer."""
        for attempt in range(tries):
            base = self.idx
            a = self.once(body)
            if a is not None and not self.cs and not repeatable:
                a = self.confirm(a)     # plain line: confirm a vector's answer [R23]
            if a is not None:
                if a.err == 0 and base is not None:
                    self.idx = (base + 1) % 256
                elif a.err != 0:
                    self.idx = None     # errors: don't assume counting [R6]
                return a
            # no (valid) answer
            self.drain()
            now = self.query_index()
            last = (now - 1) % 256 if self.at_counts else now
            if base is None or self.at_counts:
                # cannot decide by index alone
                self.idx = None
                if repeatable:          # A, V, PF ... "se dá zopakovat" [R6]
                    self.stats["resent"] += 1
                    continue
                raise Unknown(body)
            if last == base:
                self.idx = now
                self.stats["resent"] += 1
                continue                # not received: safe to send again
            if last == (base + 1) % 256:
                if not self.repeat_ok:
                    self.idx = None
                    if repeatable:
                        continue
                    raise Unknown(body)
                a, echo = self.repeat()
                if echo is not None and echo.decode("ascii", "replace").rstrip() \
                        != self.frame(body).rstrip():
                    self.idx = None
                    if repeatable:
                        continue
                    raise Unknown(body)
                self.idx = now
                self.stats["recovered"] += 1
                if a.err != 0:
                    self.idx = None
                return a
            self.check_restart()
            raise Desync("unit's command index jumped to %d (expected %d or %d): "
                         "restart or lost sync suspected, stopping" % (last, base, (base + 1) % 256))
        self.check_restart()
        raise LinkDown("no answer to %r after %d attempts" % (body, tries))

    def confirm(self, a, tries=5):
        """Without checksums a damaged '0'<->'1' cannot be seen, and would make
        us skip or repeat a vector. Ask '>' until two consecutive copies of the
        answer agree [R8][R23]. Returns None if they never agree."""
        if not self.repeat_ok:
            return a
        prev = a
        for _ in range(tries):
            try:
                b, _echo = self.repeat(tries=3)
            except LinkDown:
                return None
            if b.raw == prev.raw:
                return b
            self.stats["bad"] += 1
            prev = b
        return None

    def sync_index(self):
        self.idx = self.query_index()


class Unknown(Exception):
    """The fate of a command is unknown by index; caller decides by position."""


class Desync(Restarted):
    """Index does not fit: treated like a restart [R12]."""


# ---------------------------------------------------------------- job file
def load_job(path):
    items = []   # ("speed", n) or ("vec", (x,y,z))
    with open(path) as f:
        for no, line in enumerate(f, 1):
            s = line.split("#")[0].strip()
            if not s:
                continue
            m = re.fullmatch(r"speed\s+(\d+)", s, re.I)
            if m:
                v = int(m.group(1))
                if not 10 <= v <= 100000:   # 12.5.3 "n = 10 az 100000"
                    raise Abort("%s:%d: speed %d outside 10..100000" % (path, no, v))
                items.append(("speed", v))
                continue
            m = re.fullmatch(r"(-?\d+)\s*,\s*(-?\d+)\s*,\s*(-?\d+)", s)
            if not m:
                raise Abort("%s:%d: cannot parse %r" % (path, no, s))
            v = tuple(int(g) for g in m.groups())
            if any(abs(c) > MAX_VEC for c in v):
                raise Abort("%s:%d: vector component out of range" % (path, no))
            if v == (0, 0, 0):
                continue    # [R14] no motion; L0,0,0 is reserved as end marker
            items.append(("vec", v))
    return items


def angle_deg(a, b):
    na = math.sqrt(sum(c * c for c in a))
    nb = math.sqrt(sum(c * c for c in b))
    cosv = sum(x * y for x, y in zip(a, b)) / (na * nb)
    return math.degrees(math.acos(max(-1.0, min(1.0, cosv))))


def add(p, v):
    return tuple(a + b for a, b in zip(p, v))


# ---------------------------------------------------------------- host logic
class Host:
    def __init__(self, unit, args, out=print):
        self.u = unit
        self.a = args
        self.out = out
        self.accepted = 0          # vectors accepted by the unit
        self.expected = None       # position after all accepted vectors
        self.run = []              # (cum_before, cum_after) of vectors queued since last L

    # -- status helpers
    def ok(self, body, what=None):
        a = self.u.command(body)
        if a.err != 0:
            raise Abort("%s: unit answered error %d to %s" % (what or "setup", a.err, body))
        return a

    def flags(self):
        # F = SR6 + bit5 queue full; RUN bit 6, INTA bit 7; value read as hex [R22]
        a = self.ok("F", "status")
        return int(a.fields[0], 16)

    def position(self):
        # PF: "okamžitá absolutní poloha x,y,z", decimal [R19]
        a = self.ok("PF", "position")
        if len(a.fields) != 3:
            raise Abort("bad PF answer %r" % a.raw)
        return tuple(int(x) for x in a.fields)

    def wait_idle(self, limit):
        end = time.monotonic() + limit
        while time.monotonic() < end:
            f = self.flags()
            if f & 0x80:   # INTA
                raise Abort("motion interrupted by the unit (INTA=1, ST6=%02X)" % f)
            if not f & 0x40:   # RUN
                return
            time.sleep(0.02)
        raise Abort("motion did not end within %.0f s" % limit)

    # -- connection
    def connect(self):
        u = self.u
        u.drain(quiet=0.1, maxwait=0.5)
        # Probe with PF without checksum: plain 3 fields = checksums off, valid checksum = on [R3]
        a = None
        for _ in range(5):
            u._write(u.frame("PF", cs=False).encode())
            line = u._readline(u.timeout)
            if line is not None:
                try:
                    a = u.parse(line, cs=True)
                    if a.err != 0 or len(a.fields) == 3:
                        u.cs = True     # unit already has checksums on
                        break
                except BadAnswer:
                    pass
                try:
                    a = u.parse(line, cs=False)
                    if len(a.fields) == 3:
                        u.cs = False
                        break
                except BadAnswer:
                    pass
            a = None
            u.drain()
        if a is None:
            raise LinkDown("no answer from unit at address %s" % u.addr)
        self.identify()
        self.setup()

    def identify(self):
        # 12.5.1: '?' version, 'Q' processor id ddmmrrpp [R2]
        v = self.ok("?", "identify")
        q = self.ok("Q", "identify")
        qid = ",".join(q.fields)
        if not re.fullmatch(r"\d{8}", qid):
            raise Abort("unit id %r is not 8 digits - not a GVE84?" % qid)
        dd, mm = int(qid[0:2]), int(qid[2:4])
        if not (1 <= dd <= 31 and 1 <= mm <= 12):
            raise Abort("unit id %r is not a ddmmrrpp date code" % qid)
        ver = ",".join(v.fields)
        self.out("unit: version %r id %s" % (ver, qid))
        if "IP84" not in ver:
            self.out("warning: version string does not mention IP84 [R2]")
        self.unit_id = qid

    def setup(self):
        u = self.u
        want = self.a.checksums
        if want and not u.cs:
            # "!0%+  odpověď je už se součtem: 0,5C" [R3]
            for _ in range(5):
                u._write(u.frame("%+", cs=False).encode())
                line = u._readline(u.timeout)
                a = None
                if line is not None:
                    try:
                        a = u.parse(line, cs=True)
                    except BadAnswer:
                        u.stats["bad"] += 1
                if a is None:
                    # answer may have been checksummed but damaged: parse as cs
                    u.drain()
                    u._write(u.frame("PF", cs=True).encode())
                    line = u._readline(u.timeout)
                    try:
                        if line is not None and u.parse(line, cs=True).err == 0:
                            u.cs = True
                            break
                    except BadAnswer:
                        pass
                    u.drain()
                    continue
                if a.err != 0:
                    raise Abort("unit refused checksums: error %d" % a.err)
                u.cs = True
                break
            if not u.cs:
                raise Abort("could not switch checksums on")
            # verify with a checksummed query
            self.position()
        elif not want and u.cs:
            # "!0%-,CF  odpověď je už bez součtu: 0" - send checksummed, parse plain [R24]
            for _ in range(5):
                u._write(u.frame("%-", cs=True).encode())
                line = u._readline(u.timeout)
                try:
                    if line is not None and u.parse(line, cs=False).err == 0 \
                            and line.strip() in (b"0", b"8"):
                        break
                except BadAnswer:
                    pass
                u.drain()
            u.cs = False
            self.position()     # verify the plain link
        # calibrate the index: does '@' count itself? [R6]
        i1 = u.query_index()
        i2 = u.query_index()
        u.at_counts = (i2 != i1)
        c = 1 if u.at_counts else 0
        # does '>' run the command again (= count as a new command)? [R8]
        # @, F, @, >, @ : with a pure re-send the last step adds only c.
        self.ok("F", "status")
        i3 = u.query_index()
        u._write(u.frame(">").encode())
        u._readline(u.timeout)
        u.drain(quiet=0.05, maxwait=0.3)
        i4 = u.query_index()
        u.repeat_ok = ((i4 - i3 - c) % 256 == 0) and ((i3 - i2 - c) % 256 == 1)
        if not u.repeat_ok:
            self.out("note: '>' seems to re-run commands; recovery will use positions [R8]")
        u.idx = i4
        f = self.flags()
        if f & 0xC0:
            raise Abort("unit busy or interrupted before the job (ST6=%02X); clear it first" % f)
        # 12.5.2 "doporučená hodnota je ... asi 5 az 20 ms" [R13]
        self.ok("T%d" % self.a.dwell)
        # [R13] velocity correction for linear axes
        self.ok("VK")

    # -- vectors
    def decide_by_position(self, candidates, limit):
        """Wait for the motion to end and find which of the candidate end
        positions the unit is at (12.5.12 'exaktně dohledat') [R15]."""
        self.wait_idle(limit)
        p = self.position()
        hits = [k for k, c in enumerate(candidates) if c == p]
        if len(hits) != 1:
            raise Abort("cannot tell which vectors were executed (position %s)" % (p,))
        return hits[0]

    def send_vector(self, kind, v, limit):
        tries = 0
        end = time.monotonic() + limit
        while True:
            if self.u.idx is None:
                self.u.sync_index()
            body = "%s%d,%d,%d" % (kind, v[0], v[1], v[2])
            try:
                a = self.u.command(body, repeatable=False)
            except Unknown:
                k = self.decide_by_position([self.expected, add(self.expected, v)], limit)
                self.u.idx = None
                if k == 1:
                    self.accepted += 1
                    self.expected = add(self.expected, v)
                    return
                continue
            if a.err == 0:
                self.accepted += 1
                self.expected = add(self.expected, v)
                if a.inta:      # answer bit 3 = INTA [R20]
                    raise Abort("unit interrupted (INTA=1) after vector %d" % self.accepted)
                return
            if a.inta:
                raise Abort("unit interrupted (INTA=1); vector %d not accepted" % (self.accepted + 1))
            if a.err == 1:   # queue full / L waits for the queue [R9]
                if time.monotonic() > end:
                    raise Abort("unit queue did not free within %.0f s" % limit)
                time.sleep(0.01)
                continue
            if a.err in (2, 3, 4) and tries < 5:   # not executed: line damage [R11]
                tries += 1
                continue
            raise Abort("unit rejected vector %d %s: error %d" % (self.accepted + 1, body, a.err))

    def queued_estimate(self):
        """Vectors still in the unit (queued + executing), from RUN and the
        position [R9]. Unknown -> assume all sent are still there."""
        if not self.flags() & 0x40:
            self.run = []
            return 0
        p = self.position()
        for j, (s, e) in enumerate(self.run):
            if on_segment(p, s, e):
                del self.run[:j]
                return len(self.run)
        return len(self.run)

    def send_packet(self, vecs, limit):
        """12.3.3: !0*S, C lines, !0*E<n>; one answer '0,n' at the end [R16]."""
        u = self.u
        if u.idx is None:
            u.sync_index()
        base = u.idx
        n = len(vecs)
        frames = [u.frame("*S")] + [u.frame("C%d,%d,%d" % v) for v in vecs] + \
                 [u.frame("*E%d" % n)]
        u._write("".join(frames).encode("ascii"))
        line = u._readline(u.timeout + n * 0.02)
        a = None
        if line is not None:
            try:
                a = u.parse(line)
            except BadAnswer:
                u.stats["bad"] += 1
        else:
            u.stats["timeouts"] += 1
        cands = [self.expected]
        for v in vecs:
            cands.append(add(cands[-1], v))
        if a is None:
            u.drain()
            now = u.query_index()
            last = (now - 1) % 256 if u.at_counts else now
            d = (last - base) % 256
            u.idx = now
            if d == 0 and not u.at_counts:
                u.stats["resent"] += 1
                return 0           # nothing received: caller re-sends
            if d in (n, n + 2) and not u.at_counts and u.repeat_ok:
                a, _ = u.repeat()
                u.stats["recovered"] += 1
        u.idx = None
        if a is not None and a.err == 0 and a.fields[:1] == [str(n)]:
            self.accepted += n
            self.expected = cands[-1]
            if a.inta:
                raise Abort("unit interrupted (INTA=1) during packet")
            return n
        if a is not None and a.inta:
            raise Abort("unit interrupted (INTA=1) during packet")
        # partial/unknown outcome: find out exactly from the position [R15]
        k = self.decide_by_position(cands, limit)
        self.accepted += k
        self.expected = cands[k]
        return k

    def run_job(self, items):
        speed = None
        t_total = 0.0
        first_speed = next((n for t, n in items if t == "speed"), 1000)
        start = self.position()
        self.expected = start
        self.out("start position %d,%d,%d" % start)
        vecs = [v for t, v in items if t == "vec"]
        for t, n in items:
            if t == "speed":
                speed = n
            elif speed is None:
                speed = first_speed
            if t == "vec":
                t_total += max(abs(c) for c in n) / float(speed)
        limit = 10.0 + 2.0 * t_total + 0.05 * len(vecs)
        if not items or items[0][0] != "speed":
            self.ok("V%d" % first_speed, "speed")   # [R17] known speed from the start
        prev = None
        pending = []    # C vectors waiting to go in a packet

        def flush():
            while pending:
                room = QUEUE_SIZE - 1 - self.queued_estimate()
                if room <= 0:
                    time.sleep(0.01)
                    continue
                chunk = pending[:min(room, self.a.packet_size)]
                before = self.expected
                k = self.send_packet(chunk, limit)
                for v in chunk[:k]:
                    self.run.append((before, add(before, v)))
                    before = add(before, v)
                del pending[:k]

        for t, n in items:
            if t == "speed":
                flush()
                self.ok("V%d" % n, "speed")
                continue
            v = n
            cont = prev is not None and angle_deg(prev, v) <= self.a.corner_deg
            prev = v
            if cont and self.a.packets:
                pending.append(v)
                if len(pending) >= self.a.packet_size:
                    flush()
                continue
            flush()
            before = self.expected
            self.send_vector("C" if cont else "L", v, limit)
            if not cont:
                self.run = []
            self.run.append((before, self.expected))
        flush()
        # 12.5.2: "L0,0,0 ... Dokud není přijat, karta hlásí chybu 1" - end marker
        self.send_vector("L", (0, 0, 0), limit)
        self.accepted -= 1          # the marker is not a job vector
        self.wait_idle(limit)
        pos = self.position()
        # compare with the start position read by PF, no N zeroing [R19]
        want = add(start, tuple(sum(c) for c in zip((0, 0, 0), *vecs))) if vecs else start
        self.out("final position %d,%d,%d" % pos)
        self.out("vectors accepted %d/%d; link: %s" % (self.accepted, len(vecs), self.u.stats))
        if self.accepted != len(vecs):
            raise Abort("only %d of %d vectors executed" % (self.accepted, len(vecs)))
        if pos != want:
            raise Abort("final position %s differs from the job's %s" % (pos, want))
        return pos


def on_segment(p, s, e, tol=2.0):
    d = [b - a for a, b in zip(s, e)]
    w = [b - a for a, b in zip(s, p)]
    dd = sum(c * c for c in d)
    if dd == 0:
        return all(abs(c) <= tol for c in w)
    t = sum(x * y for x, y in zip(w, d)) / dd
    if t < -1e-9 or t > 1 + 1e-9:
        return False
    dist = math.sqrt(sum((w[i] - t * d[i]) ** 2 for i in range(3)))
    return dist <= tol and (p != e)


def main(argv=None):
    ap = argparse.ArgumentParser(description="GVE84 host")
    ap.add_argument("port")
    ap.add_argument("job")
    ap.add_argument("--baud", type=int, default=38400)       # [R1][R25]
    ap.add_argument("--address", type=int, default=0)        # 12.5 "0-7" [R21]
    ap.add_argument("--checksums", action="store_true")
    ap.add_argument("--packets", action="store_true")
    ap.add_argument("--packet-size", type=int, default=10)
    ap.add_argument("--timeout", type=float, default=None)
    ap.add_argument("--corner-deg", type=float, default=10.0)  # [R18]
    ap.add_argument("--dwell", type=int, default=10)           # [R13]
    ap.add_argument("--verbose", action="store_true")
    a = ap.parse_args(argv)
    if not 0 <= a.address <= 7:
        print("error: address must be 0..7", file=sys.stderr)
        return 2
    if not 1 <= a.dwell <= 24:
        print("error: dwell must be 1..24 ms", file=sys.stderr)
        return 2
    a.packet_size = max(1, min(a.packet_size, QUEUE_SIZE - 2))
    log = (lambda s: print(s, file=sys.stderr)) if a.verbose else None
    try:
        items = load_job(a.job)
        fd = open_port(a.port, a.baud)
        unit = Unit(fd, a.address, a.baud, a.timeout, log)
        host = Host(unit, a)
        attempts = 0
        while True:
            try:
                host.connect()
                host.run_job(items)
                break
            except Restarted as e:
                if host.accepted:
                    raise Abort("%s; %d vectors had been accepted, position lost, "
                                "not re-sending" % (e, host.accepted))
                if attempts >= 2:
                    raise
                attempts += 1
                time.sleep(2.5)   # 12.4 "cca po 2s ve stavu" - then set up again
    except (Abort, OSError) as e:
        print("FAILED: %s" % e, file=sys.stderr)
        return 1
    print("OK")
    return 0


if __name__ == "__main__":
    sys.exit(main())
