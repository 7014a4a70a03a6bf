#!/usr/bin/env python3
"""Host program for the GVE114 4-axis interpolation unit (serial protocol, manual ch. 13).

usage: host.py PORT JOBFILE [--baud N] [--address A] [--checksums] [--packets]
                            [--packet-size K] [--timeout S] [--tcorner MS] [-v]

Readings of the manual are numbered [Rn] and explained in READINGS.md.
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
CR = b"\r"                     # [R2]
BAUDS = {19200: termios.B19200, 38400: termios.B38400, 57600: termios.B57600,
         115200: termios.B115200}
for _n in (230400, 460800, 921600):
    _c = getattr(termios, "B%d" % _n, None)
    if _c is not None:
        BAUDS[_n] = _c

MAXV = 2147483647
ERRTXT = {0: "OK", 1: "queue full", 2: "command not complete in time (watchdog)",
          3: "unknown command", 4: "syntax error", 5: "parameter out of range",
          6: "nothing to GO", 7: "not possible while running"}


class Fatal(Exception):
    """Stop the job; message is the one-line reason."""


class LineFault(Exception):
    """An answer was lost, cut or damaged (timeout / bad checksum / garbage)."""


class NoChecksum(LineFault):
    """Checksums are on but an answer came without one: the unit has probably restarted [R14]."""


# ---------------------------------------------------------------- framing
def checksum(text):
    """Sum of all ASCII codes modulo 256 (text already ends with the comma) [manual 13.3.2]."""
    return sum(text.encode("ascii")) & 0xFF


def build_frame(address, cmd, checks):
    """'!' address command [params] Enter; with checksums the Enter is replaced by ',' + 2 hex
    digits + Enter [R3]."""
    body = "!%d%s" % (address, cmd)
    if checks:
        body += ","
        body += "%02X" % checksum(body)
    return body.encode("ascii") + CR


def parse_answer(raw, checks):
    """Answer: one hex digit (bit3=INTA, bits2..0 = error code) [,params] [,checksum] Enter.
    Returns (inta, code, [params]). Raises LineFault on anything malformed [R4]."""
    try:
        s = raw.decode("ascii")
    except UnicodeDecodeError:
        raise LineFault("non-ASCII answer %r" % raw)
    s = s.strip("\r\n")
    if checks:
        k = s.rfind(",")
        if k < 0:
            if len(s) == 1 and s in "0123456789ABCDEF":
                raise NoChecksum("answer %r without checksum" % s)
            raise LineFault("answer %r without checksum" % s)
        cs = s[k + 1:]
        if not (1 <= len(cs) <= 2) or any(c not in "0123456789ABCDEFabcdef" for c in cs):
            raise LineFault("bad checksum field in %r" % s)
        if int(cs, 16) != checksum(s[:k + 1]):
            raise LineFault("checksum mismatch in %r" % s)
        s = s[:k]
    if not s or s[0] not in "0123456789ABCDEF":
        raise LineFault("garbled answer %r" % s)
    if len(s) > 1 and s[1] != ",":
        raise LineFault("garbled answer %r" % s)
    v = int(s[0], 16)
    params = s[2:].split(",") if len(s) > 2 else []
    return (v >> 3) & 1, v & 7, params


def parse_job(path):
    """Returns list of ('speed', n) / ('vec', (dx,dy,dz,da))."""
    items = []
    with open(path) as f:
        for no, line in enumerate(f, 1):
            t = line.split("#")[0].strip()
            if not t:
                continue
            try:
                if t.lower().startswith("speed"):
                    n = int(t[5:].strip())
                    if not 10 <= n <= 100000:           # [manual 13.6.3: n = 10 az 100000]
                        raise ValueError("speed out of 10..100000")
                    items.append(("speed", n))
                else:
                    v = tuple(int(p) for p in t.split(","))
                    if len(v) != 4:
                        raise ValueError("need 4 components")
                    if any(abs(c) > MAXV for c in v):
                        raise ValueError("component out of +-2147483647")
                    items.append(("vec", v))
            except ValueError as e:
                raise Fatal("job line %d: %s (%r)" % (no, e, t))
    return items


# ---------------------------------------------------------------- serial port
class Port:
    def __init__(self, path, baud):
        if baud not in BAUDS:
            raise Fatal("baud %d not supported here (%s)" % (baud, sorted(BAUDS)))
        try:
            self.fd = os.open(path, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
        except OSError as e:
            raise Fatal("cannot open %s: %s" % (path, e.strerror))
        a = termios.tcgetattr(self.fd)
        # raw 8N1 [manual 13.3: 8 bitu, 1 stop bit, bez parity]
        a[0] = termios.IGNBRK                      # iflag
        a[1] = 0                                   # oflag
        a[2] = termios.CS8 | termios.CREAD | termios.CLOCAL   # cflag: 8N1, no flow control
        a[3] = 0                                   # lflag
        a[4] = a[5] = BAUDS[baud]
        a[6][termios.VMIN] = 0
        a[6][termios.VTIME] = 0
        termios.tcsetattr(self.fd, termios.TCSANOW, a)
        self.buf = b""

    def flush_input(self):
        self.buf = b""
        try:
            termios.tcflush(self.fd, termios.TCIFLUSH)
        except termios.error:
            pass
        while True:
            r, _, _ = select.select([self.fd], [], [], 0)
            if not r:
                break
            try:
                if not os.read(self.fd, 4096):
                    break
            except OSError:
                break

    def write(self, data):
        view = memoryview(data)
        while view:
            _, w, _ = select.select([], [self.fd], [], 1.0)
            if not w:
                raise Fatal("serial port does not accept data")
            try:
                n = os.write(self.fd, view)
            except BlockingIOError:
                continue
            view = view[n:]

    def readline(self, timeout):
        end = time.monotonic() + timeout
        while True:
            k = self.buf.find(CR)
            if k >= 0:
                line, self.buf = self.buf[:k], self.buf[k + 1:]
                return line.lstrip(b"\n")
            left = end - time.monotonic()
            if left <= 0:
                raise LineFault("timeout, no answer (partial %r)" % self.buf)
            r, _, _ = select.select([self.fd], [], [], left)
            if r:
                try:
                    d = os.read(self.fd, 4096)
                except (BlockingIOError, InterruptedError):
                    continue
                except OSError as e:
                    raise Fatal("serial port read error: %s" % e.strerror)
                self.buf += d


# ---------------------------------------------------------------- unit protocol
class Unit:
    def __init__(self, port, address, checks, timeout, verbose=False):
        self.port = port
        self.addr = address
        self.checks = False            # after power-up/reset checksums are off [manual 13.3.2]
        self.want_checks = checks
        self.timeout = timeout
        self.verbose = verbose
        self.idx = None                # our copy of the unit's command index [R8]
        self.at_counts = False         # does '@' count itself? calibrated [R9]
        self.inta_seen = False
        self._tracking = False         # set once the index has been calibrated
        self.index_reliable = False

    def log(self, *a):
        if self.verbose:
            print("  ", *a, file=sys.stderr)

    def once(self, cmd, checks=None, timeout=None):
        """One command, one answer (strictly simplex [manual 13.3.1]). May raise LineFault."""
        if checks is None:
            checks = self.checks
        self.port.flush_input()        # drop late answers of earlier commands [R7]
        frame = build_frame(self.addr, cmd, checks)
        self.log(">>", frame)
        self.port.write(frame)
        raw = self.port.readline(timeout or self.timeout)
        self.log("<<", raw)
        res = parse_answer(raw, checks)
        if self.idx is not None and not cmd.startswith("@"):
            self.idx = (self.idx + 1) & 0xFF
        elif self.idx is not None and self.at_counts:
            self.idx = (self.idx + 1) & 0xFF
        if res[0]:
            self.inta_seen = True
        return res

    def query(self, cmd, tries=6, ok_codes=(0,)):
        """Repeatable command (query / modal setting): on a line fault simply send it again
        [manual 13.6.13: 'Vetsina prikazu se da zopakovat (A,V,PF atd..)'] [R10]."""
        last = None
        for _ in range(tries):
            try:
                inta, code, params = self.once(cmd)
            except NoChecksum as e:
                raise Fatal("unit answered without checksum - it has restarted (%s)" % e)
            except LineFault as e:
                last = e
                self.idx = None            # unknown whether the unit counted it; resync later
                time.sleep(0.02)
                continue
            if code not in ok_codes:
                raise Fatal("unit refused %s: error %d (%s)" % (cmd, code, ERRTXT.get(code)))
            if last is not None and self.idx is None and not cmd.startswith("@") \
                    and self.at_counts is not None and self._tracking:
                self.idx = self.read_index()       # resynchronise the index after a fault
            return inta, code, params
        if self.checks:
            # every answer failed its checksum: does the unit answer *without* checksums?
            # Then it has restarted (checksums are off after reset) [R14].
            try:
                inta, code, params = self.once(cmd, checks=False)
                raise Fatal("unit answers without checksums - it has restarted (power/reset); "
                            "position and queue are lost")
            except LineFault:
                pass
        raise Fatal("no valid answer to %s after %d tries (%s)" % (cmd, tries, last))

    def read_index(self):
        """'@' -> index of the last command, modulo 256 [R8]."""
        _, _, p = self.query("@")
        if not p:
            raise Fatal("'@' answer without index")
        t = p[0].strip()
        try:
            v = int(t, 16) if any(c in "ABCDEFabcdef" for c in t) else int(t)
        except ValueError:
            raise Fatal("'@' answer %r not a number" % t)
        return v & 0xFF

    def flags(self):
        """F = SR6 + bit5 queue full. Returns (run, inta, full)."""
        _, _, p = self.query("F")
        if not p:
            raise Fatal("F answer without value")
        try:
            v = int(p[0], 16)                     # [R11] status bytes are hex
        except ValueError:
            raise Fatal("F answer %r not hex" % p[0])
        return (v >> 6) & 1, (v >> 7) & 1, (v >> 5) & 1

    def position(self):
        """PF -> x,y,z (the unit cannot report A) [R12]."""
        _, _, p = self.query("PF")
        try:
            return tuple(int(x) for x in p[:3]) if len(p) >= 3 else None
        except ValueError:
            return None


# ---------------------------------------------------------------- job runner
class Runner:
    def __init__(self, unit, items, packets, packet_size, verbose):
        self.u = unit
        self.items = items
        self.packets = packets
        self.packet_size = packet_size
        self.verbose = verbose
        self.vectors_sent = 0          # vectors known to be accepted exactly once
        self.expect = None             # expected x,y,z after all accepted vectors finish
        self.a_sum = 0

    # --- connection / identification / setup
    def connect(self):
        u = self.u
        # Unknown whether a previous session left checksums on: try switching them off
        # both with and without a checksum [R5].
        for chk in (True, False):
            try:
                u.once("%-", checks=chk)
            except LineFault:
                pass
        u.checks = False
        inta, code, p = u.query("?")
        ver = ",".join(p)
        if "114" not in ver:                                     # [R6]
            raise Fatal("unit at address %d is not a GVE114 (version %r)" % (u.addr, ver))
        _, _, q = u.query("Q")
        qid = ",".join(q)
        if not (len(qid) == 8 and qid.isdigit()):
            raise Fatal("unit ID %r is not 8 digits ddmmrrpp" % qid)
        print("unit: %s, ID %s (made %s.%s.20%s, #%s)" % (ver, qid, qid[0:2], qid[2:4],
                                                         qid[4:6], qid[6:8]))
        if self.u.want_checks:
            # '!0%+' is sent without checksum, the answer already has one [manual 13.3.2]
            for _ in range(6):
                try:
                    inta, code, _ = u.once("%+", checks=False)
                    break
                except LineFault:
                    try:                    # maybe it did switch: check with a checksummed '?'
                        u.once("?", checks=True)
                        break
                    except LineFault:
                        continue
            else:
                raise Fatal("could not switch checksums on")
            u.checks = True
        run, inta, full = u.flags()
        if run:
            raise Fatal("unit is running (RUN=1) - another job is active")
        if inta:                                                 # [R13]
            raise Fatal("unit is in interrupted state (INTA=1); clear it (D/G) deliberately first")
        # calibrate the index: does '@' count itself? [R9]
        u.idx = None
        a = u.read_index()
        b = u.read_index()
        if b == a:
            u.at_counts = False
        elif b == (a + 1) & 0xFF:
            u.at_counts = True
        else:
            raise Fatal("index behaves oddly (%d then %d)" % (a, b))
        u.idx = b
        u._tracking = True
        # does an ordinary command (F) move the index by one? if not, the index cannot be
        # tracked and every recovery is settled by position [R8]
        self.u.flags()
        c = u.read_index()
        u.index_reliable = (c == (b + 1 + (1 if u.at_counts else 0)) & 0xFF)
        u.idx = c
        if not u.index_reliable:
            print("note: unit's index does not count every command; recovery by position only")
        # setup as the manual advises [R15]
        u.query("A20")          # 20 000 steps/s^2, the reset value, stated explicitly
        u.query("T10")          # pause between L vectors, 5..20 ms advised
        u.query("V1000")        # reset value until the job's first 'speed'
        u.query("B10")
        self.expect = u.position()
        if self.expect is None:
            raise Fatal("PF answer unreadable")
        print("start position X,Y,Z = %d,%d,%d" % self.expect)

    # --- helpers
    def wait_idle(self, limit):
        """Poll F until RUN=0 [manual 13.6.12]."""
        end = time.monotonic() + limit
        while True:
            run, inta, full = self.u.flags()
            if inta:
                raise Fatal("unit interrupted (INTA=1: STOP/limit/interrupt input) - job stopped")
            if not run:
                return
            if time.monotonic() > end:
                raise Fatal("motion did not end within %.0f s" % limit)
            time.sleep(0.02)

    def wait_room(self, limit=600):
        """Wait while the queue is full (F bit5) [manual 13.6.12, code 1]."""
        end = time.monotonic() + limit
        while True:
            run, inta, full = self.u.flags()
            if inta:
                raise Fatal("unit interrupted (INTA=1) - job stopped")
            if not full:
                return
            if time.monotonic() > end:
                raise Fatal("queue stays full")
            time.sleep(0.01)

    def settle_by_position(self, vecs, why, index_odd=False):
        """Decide how many of `vecs` (in order) were accepted, by letting the queue run
        empty and comparing PF with the expected prefix sums [R16]."""
        self.u.log("verifying by position:", why)
        self.wait_idle(self.time_limit)
        pos = self.u.position()
        if pos is None:
            raise Fatal("PF unreadable during recovery")
        if index_odd and pos == (0, 0, 0):
            # index jumped and the counters read zero: the unit has been reset [R14]
            raise Fatal("unit has restarted during the job (index jumped, counters zero); "
                        "not repeating any vector")
        matches = []
        acc = list(self.expect)
        for k in range(len(vecs) + 1):
            if tuple(acc) == pos:
                matches.append(k)
            if k < len(vecs):
                acc = [acc[i] + vecs[k][i] for i in range(3)]
        if len(matches) != 1:
            raise Fatal("cannot tell after %s whether vector(s) were executed (position %s, "
                        "candidates %s) - unit restarted or steps lost" % (why, pos, matches))
        # index is unknown now; resynchronise
        self.u.idx = self.u.read_index()
        return matches[0]

    def accept(self, vecs):
        for v in vecs:
            self.expect = tuple(self.expect[i] + v[i] for i in range(3))
            self.a_sum += v[3]
            self.vectors_sent += 1

    @staticmethod
    def fmt_vec(v):
        return "C%d,%d,%d,%d" % v                                  # [R17]

    def brake_for(self, v, nxt, speed):
        """Brake speed at the end of v, from the angle to the next vector [R18]."""
        if nxt is None:
            return 10
        n1 = math.sqrt(sum(c * c for c in v))
        n2 = math.sqrt(sum(c * c for c in nxt))
        if n1 == 0 or n2 == 0:
            return 10
        cos = sum(a * b for a, b in zip(v, nxt)) / (n1 * n2)
        if cos <= 0:
            return 10
        return max(10, min(speed, int(speed * cos ** 4)))

    # --- single vector, without packets
    def send_vector(self, v):
        u = self.u
        cmd = self.fmt_vec(v)
        refused = 0
        for attempt in range(50):
            before = u.idx
            try:
                inta, code, _ = u.once(cmd)
            except NoChecksum as e:
                raise Fatal("unit has restarted during the job (%s); not repeating any vector" % e)
            except LineFault as e:
                u.log("line fault on vector:", e)
                k = self.recover_single(v, before, str(e))
                if k == 1:
                    return
                continue                                 # certainly not executed: send again
            if inta:                                     # STOP / interrupt input [R26]
                raise Fatal("unit interrupted (INTA=1) while feeding - job stopped")
            if code == 0:
                self.accept([v])
                return
            if u.index_reliable:
                u.idx = u.read_index()     # refused commands may or may not count [R8]
            if code == 1:     # queue full: not accepted, wait and repeat [R25]
                if not u.checks:
                    # without checksums a damaged '0' can read as '1' [R23]: cross-check F
                    run, inta2, full = u.flags()
                    if not full:
                        k = self.settle_by_position([v], "answer 1 but queue not full")
                        if k == 1:
                            self.accept([v])
                            return
                        continue
                self.wait_room()
                continue
            if code in (2, 3, 4, 5):
                # 2 = frame cut short (watchdog) [R19]; 3/4/5 for a frame we built valid means
                # it was damaged on the line (checksum refusal code is not given) [R20]:
                # the unit did not execute it, so sending it again is safe.
                refused += 1
                if refused <= 8:
                    continue
            raise Fatal("unit refused vector %s: error %d (%s)" % (cmd, code, ERRTXT.get(code)))
        raise Fatal("vector %s could not be delivered" % cmd)

    def recover_single(self, v, before, why):
        """Answer to a vector was lost/damaged: ask the index [manual 13.6.13 '@'] [R8][R10]."""
        u = self.u
        time.sleep(0.05)
        try:
            now = u.read_index()
        except Fatal:
            raise
        k_at = 1 if u.at_counts else 0
        if not u.index_reliable:
            before = None
        if before is not None:
            if now == (before + k_at) & 0xFF:
                u.idx = now
                return 0                                 # never arrived: safe to send again
            if now == (before + 1 + k_at) & 0xFF and not any(v[:3]):
                # A-only vector: position cannot tell; trust the index [R16]
                u.idx = now
                self.accept([v])
                return 1
        odd = before is not None and now not in ((before + k_at) & 0xFF, (before + 1 + k_at) & 0xFF)
        k = self.settle_by_position([v], why, index_odd=odd)
        if k == 1:
            self.accept([v])
        return k

    # --- packets
    def send_packet(self, cmds):
        """cmds: list of ('B', n) / ('C', vec). Only B and C may be in a packet [manual 13.4]."""
        u = self.u
        while cmds:
            frames = [build_frame(u.addr, "*S", u.checks)]
            for kind, val in cmds:
                frames.append(build_frame(u.addr, "B%d" % val if kind == "B" else
                                          self.fmt_vec(val), u.checks))
            frames.append(build_frame(u.addr, "*E%d" % len(cmds), u.checks))
            vecs = [val for kind, val in cmds if kind == "C"]
            before = u.idx
            # the whole packet goes in one write and gets one answer after '*E' [R28][R21]
            u.port.flush_input()
            data = b"".join(frames)
            u.log(">>", data)
            u.port.write(data)
            try:
                raw = u.port.readline(u.timeout + len(data) * 12.0 / u.baud + 0.002 * len(cmds))
                u.log("<<", raw)
                inta, code, p = parse_answer(raw, u.checks)
            except NoChecksum as e:
                raise Fatal("unit has restarted during the job (%s); not repeating any vector" % e)
            except LineFault as e:
                u.idx = None
                now = u.read_index()
                if before is not None and u.index_reliable and now == (before + (1 if u.at_counts else 0)) & 0xFF:
                    u.idx = now
                    continue                             # nothing of it arrived: resend
                k = self.settle_by_position(vecs, "packet answer fault (%s)" % e)
                cmds = self.drop_vectors(cmds, k)
                continue
            if inta:
                raise Fatal("unit interrupted (INTA=1) while feeding - job stopped")
            u.idx = None
            try:
                count = int(p[0]) if p else None         # [R21]
            except ValueError:
                count = None
            if code == 0 and count == len(cmds):
                self.accept(vecs)
                u.idx = u.read_index()
                return
            if code == 1 and count is not None and 0 <= count < len(cmds):
                done = cmds[:count]
                self.accept([val for kind, val in done if kind == "C"])
                cmds = cmds[count:]
                u.idx = u.read_index()
                self.wait_room()
                continue
            if code in (2, 4) and count in (None, 0):
                # whole packet refused (cut short / damaged): check by position to be sure
                k = self.settle_by_position(vecs, "packet error %d" % code)
                cmds = self.drop_vectors(cmds, k)
                continue
            raise Fatal("unit refused packet: error %d (%s), count %r" %
                        (code, ERRTXT.get(code), count))

    def drop_vectors(self, cmds, k):
        """Remove the first k vectors (accepted) from cmds, keep the rest."""
        out, seen = [], 0
        for kind, val in cmds:
            if kind == "C" and seen < k:
                self.accept([val])
                seen += 1
                continue
            out.append((kind, val))
        # drop B commands before the first remaining C that have no effect any more
        return out if any(kind == "C" for kind, _ in out) else []

    # --- whole job
    def run(self):
        u = self.u
        items = self.items
        vec_list = [v for kind, v in items if kind == "vec"]
        total_steps = sum(max(abs(c) for c in v) for v in vec_list)
        self.time_limit = 30 + 3.0 * total_steps / 10.0      # slowest possible speed is 10/s
        speed = 1000                                        # reset value [manual 13.5]
        cur_b = 10
        pending = []
        # next vector lookup for brake computation
        nxt_of = {}
        last = None
        for i, (kind, v) in enumerate(items):
            if kind == "vec":
                if last is not None:
                    nxt_of[last] = v
                last = i
        for i, (kind, val) in enumerate(items):
            if kind == "speed":
                if pending:
                    self.send_packet(pending)
                    pending = []
                u.query("V%d" % val)                 # modal, repeatable; never inside a packet [R27]
                speed = val
                continue
            b = self.brake_for(val, nxt_of.get(i), speed)
            if self.packets:
                if b != cur_b:
                    pending.append(("B", b))
                    cur_b = b
                pending.append(("C", val))
                if len(pending) >= self.packet_size:
                    self.send_packet(pending)
                    pending = []
            else:
                if b != cur_b:
                    u.query("B%d" % b)
                    cur_b = b
                self.send_vector(val)
        if pending:
            self.send_packet(pending)
        # end marker L0,0,0: refused with 1 until the queue before it is done [R24]
        end = time.monotonic() + self.time_limit
        while True:
            try:
                inta, code, _ = u.once("L0,0,0,0")
            except NoChecksum as e:
                raise Fatal("unit has restarted during the job (%s)" % e)
            except LineFault:
                time.sleep(0.02)
                continue                            # zero vector: repeating it moves nothing
            if inta:
                raise Fatal("unit interrupted (INTA=1) - job stopped")
            if code == 0:
                break
            if code != 1 and code != 2 and not (code == 4 and u.checks):
                raise Fatal("end marker L0,0,0 refused: error %d (%s)" % (code, ERRTXT.get(code)))
            if time.monotonic() > end:
                raise Fatal("queue did not finish in time")
            time.sleep(0.02)
        self.wait_idle(self.time_limit)
        pos = u.position()
        if pos is None:
            raise Fatal("final PF unreadable")
        print("final position X,Y,Z = %d,%d,%d  (A: +%d steps commanded, unit cannot report A)"
              % (pos + (self.a_sum,)))
        print("vectors executed: %d of %d" % (self.vectors_sent, len(vec_list)))
        if self.vectors_sent != len(vec_list):
            raise Fatal("only %d of %d vectors executed" % (self.vectors_sent, len(vec_list)))
        if pos != self.expect:
            raise Fatal("final position %s differs from expected %s" % (pos, self.expect))


def main(argv=None):
    ap = argparse.ArgumentParser(description="GVE114 job host")
    ap.add_argument("port")
    ap.add_argument("job")
    ap.add_argument("--baud", type=int, default=DEFAULT_BAUD)
    ap.add_argument("--address", type=int, default=0)
    ap.add_argument("--checksums", action="store_true")
    ap.add_argument("--packets", action="store_true")
    ap.add_argument("--packet-size", type=int, default=10)
    ap.add_argument("--timeout", type=float, default=0.5, help="answer timeout in s [R7]")
    ap.add_argument("-v", "--verbose", action="store_true")
    a = ap.parse_args(argv)
    try:
        if not 0 <= a.address <= 6:                      # [R22]
            raise Fatal("address must be 0..6 (7 is the spindle channel)")
        if a.packet_size < 1:
            raise Fatal("packet size must be >= 1")
        items = parse_job(a.job)
        port = Port(a.port, a.baud)
        unit = Unit(port, a.address, a.checksums, a.timeout, a.verbose)
        unit.baud = a.baud
        r = Runner(unit, items, a.packets, a.packet_size, a.verbose)
        r.connect()
        r.run()
    except Fatal as e:
        print("host114: FAILED: %s" % e, file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("host114: FAILED: interrupted by user", file=sys.stderr)
        return 3
    print("host114: OK, job finished at the expected position")
    return 0


if __name__ == "__main__":
    sys.exit(main())
