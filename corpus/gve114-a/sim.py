#!/usr/bin/env python3
"""GVE114 simulator: co-simulation driver (given/cosim.md + given/rig.md).

    python3 sim.py --cosim [--model GVE114-500] [--eeprom FILE]

Virtual time only: the clock moves with the commands on standard input.
"""
import argparse
import json
import re
import sys
from collections import deque

from unit import Unit, MODELS

NUM_RE = re.compile(r'[0-9]{1,20}$')
SNUM_RE = re.compile(r'[+-]?[0-9]{1,20}$')
HEXB_RE = re.compile(r'[0-9A-Fa-f]{2}$')
INF = float('inf')


class CmdError(Exception):
    pass


class Line:
    """The serial line between the host and the unit, in virtual time."""

    def __init__(self, unit, baud=115200):
        self.unit = unit
        self.now = 0
        self.baud = baud
        self.b = round(1e10 / baud)
        self.inq = deque()            # (instant complete at the unit, byte)
        self.outq = deque()           # bytes handed over, not yet begun
        self.cur = None               # (instant complete at the host, byte)
        self.reported = []
        unit.send = self._send

    def _send(self, t, data):
        self.outq.extend(data)
        if self.cur is None:
            self.cur = (t + self.b, self.outq.popleft())

    def _rate_ok(self):
        r = self.unit.rate
        return r is None or abs(r - self.baud) <= 0.025 * r

    def advance(self, limit, cr_stop):
        """Run the clock to limit; return True if stopped at a CR."""
        u = self.unit
        while True:
            te = u.next_event()
            te = INF if te is None else te
            ti = self.inq[0][0] if self.inq else INF
            to = self.cur[0] if self.cur else INF
            t = min(te, ti, to)
            if t > limit:
                break
            self.now = t
            if te == t:
                u.fire(t)
                continue
            if ti == t:
                _, byte = self.inq.popleft()
                if self._rate_ok():
                    u.receive(t, byte)
                continue
            _, byte = self.cur
            self.reported.append((t, byte))
            self.cur = (t + self.b, self.outq.popleft()) if self.outq else None
            if byte == 0x0D and cr_stop:
                return True
        self.now = limit
        return False

    def take_rx(self):
        out = []
        group = None
        for t, byte in self.reported:
            if group and t == group[0] + len(group[1]) * self.b:
                group[1].append(byte)
            else:
                group = [t, [byte]]
                out.append(group)
        self.reported = []
        return ['rx %d %s' % (t, bytes(bs).hex().upper()) for t, bs in out]

    # -------------------------------------------------------------- commands
    def tx(self, hexs, T=None):
        data = parse_hex(hexs)
        end = self.now + len(data) * self.b
        if T is not None and T < end:
            raise CmdError('T before the end of the bytes')
        for i, byte in enumerate(data):
            self.inq.append((self.now + (i + 1) * self.b, byte))
        self.advance(end, cr_stop=False)
        got_cr = any(b == 0x0D for _, b in self.reported)
        if T is not None and not got_cr:
            got_cr = self.advance(T, cr_stop=True)
        return self.take_rx() + ['now %d' % self.now], got_cr

    def next_instant(self):
        te = self.unit.next_event()
        c = [x for x in (te, self.cur[0] if self.cur else None) if x is not None]
        c = [x for x in c if x > self.now] or c
        return min(c) if c else None


def parse_hex(s):
    if len(s) % 2 or not re.fullmatch(r'[0-9A-Fa-f]*', s) or not s:
        raise CmdError('bad hex')
    return bytes.fromhex(s)


def num(s):
    if not NUM_RE.match(s):
        raise CmdError('bad number %r' % s)
    return int(s)


class Sim:
    def __init__(self, model, eeprom=None):
        data = None
        self.eeprom_path = eeprom
        if eeprom:
            try:
                with open(eeprom, 'rb') as f:
                    data = f.read()[:256].ljust(256, b'\xff')
            except OSError:
                data = None
        self.unit = Unit(model, data)
        self.line = Line(self.unit)

    def handle(self, words):
        u, ln = self.unit, self.line
        cmd = words[0].lower()
        args = words[1:]
        if args and args[-1].startswith('@'):
            a = args[-1][1:]
            if a not in ('0', '7'):
                raise CmdError('no unit at address %s' % a)
            args = args[:-1]
        if cmd == 'tx':
            if len(args) not in (1, 2):
                raise CmdError('tx HEX [T]')
            data = parse_hex(args[0])
            T = num(args[1]) if len(args) == 2 else None
            if T is not None and T < ln.now + len(data) * ln.b:
                raise CmdError('T before the end of the bytes')
            lines, _ = ln.tx(args[0], T)
            return lines
        if cmd == 'batch':
            if not args or len(args) % 2:
                raise CmdError('batch D HEX [D HEX ...]')
            pairs = []
            for i in range(0, len(args), 2):
                pairs.append((num(args[i]), parse_hex(args[i + 1]), args[i + 1]))
            out = []
            for D, data, hx in pairs:
                end = ln.now + len(data) * ln.b
                lines, got = ln.tx(hx, end + D)
                out.extend(lines)
                if not got:
                    break
            return out
        if cmd == 'until':
            if len(args) != 1:
                raise CmdError('until T')
            T = num(args[0])
            if T < ln.now:
                raise CmdError('until before now')
            ln.advance(T, cr_stop=True)
            return ln.take_rx() + ['now %d' % ln.now]
        if cmd == 'next':
            if args:
                raise CmdError('next takes no argument')
            t = ln.next_instant()
            return ['next none' if t is None else 'next %d' % t]
        if cmd == 'baud':
            if len(args) != 1:
                raise CmdError('baud N')
            n = num(args[0])
            if n <= 0:
                raise CmdError('bad rate')
            ln.baud = n
            ln.b = round(1e10 / n)
            return ['ok']
        if cmd == 'state':
            if args:
                raise CmdError('state takes no argument')
            st = u.state(ln.now)
            st['eeprom'] = self.eeprom_path
            return [json.dumps(st)]
        if cmd == 'in':
            if len(args) != 2 or not NUM_RE.match(args[0]) or not HEXB_RE.match(args[1]):
                raise CmdError('in PORT XX')
            port = int(args[0])
            if port > 2:
                raise CmdError('no input port %d' % port)
            u.rig_in(ln.now, port, int(args[1], 16))
            return ['ok']
        if cmd == 'switch':
            if len(args) != 2 or args[0].upper() not in ('X', 'Y', 'Z', 'A'):
                raise CmdError('switch AXIS POS|none')
            if args[1] == 'none':
                u.switches[args[0].upper()] = None
            else:
                if not SNUM_RE.match(args[1]):
                    raise CmdError('bad position')
                u.switches[args[0].upper()] = int(args[1])
            return ['ok']
        if cmd == 'rate':
            if len(args) != 1:
                raise CmdError('rate POS|none')
            if args[0] == 'none':
                u.rate_position = None
            else:
                p = num(args[0])
                if p > 3:
                    raise CmdError('the GVE114 rate switch has positions 0..3')
                u.rate_position = p
            return ['ok']
        if cmd == 'power-on':
            if args:
                raise CmdError('power-on takes no argument')
            u.rig_power_on(ln.now)
            return ['ok']
        if cmd == 'help':
            return ['commands: tx HEX [T] | batch D HEX ... | until T | next | baud N | '
                    'in PORT HEX | switch AXIS POS|none | rate POS|none | power-on | '
                    'state | quit']
        raise CmdError('unknown command %r' % words[0])

    def save_eeprom(self):
        if self.eeprom_path:
            try:
                with open(self.eeprom_path, 'wb') as f:
                    f.write(bytes(self.unit.eeprom))
            except OSError:
                pass


def main():
    ap = argparse.ArgumentParser(description='GVE114 co-simulator')
    ap.add_argument('--cosim', action='store_true', help='speak cosim 1 on stdin/stdout')
    ap.add_argument('--model', default='GVE114-500', choices=sorted(MODELS))
    ap.add_argument('--eeprom', default=None, help='EEPROM image file (kept across runs)')
    a = ap.parse_args()
    if not a.cosim:
        ap.error('only --cosim (virtual time) is implemented')
    sim = Sim(a.model, a.eeprom)
    out = sys.stdout
    out.write('cosim 1 batch batch-stops\n')
    out.flush()
    for raw in sys.stdin:
        line = raw.rstrip('\n').rstrip('\r')
        words = line.split()
        if not words:
            continue
        if words[0].lower() in ('quit', 'exit'):
            break
        try:
            replies = sim.handle(words)
        except CmdError as e:
            replies = ['error: %s' % e]
        except Exception as e:  # never die on a command
            replies = ['error: internal: %r' % (e,)]
        out.write('\n'.join(replies) + '\n')
        out.flush()
    sim.save_eeprom()
    return 0


if __name__ == '__main__':
    sys.exit(main())
