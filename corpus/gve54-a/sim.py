#!/usr/bin/env python3
"""GVE54 (firmware Ip54v3) simulator speaking the co-simulation protocol.

    python3 sim.py --cosim [--address 0] [--baud 115200]

Virtual time only: the clock moves with the commands on standard input
(given/cosim.md), the test rig's commands are those of given/rig.md.
"""

import argparse
import json
import re
import sys
from collections import deque

from unit import Unit

INF = float("inf")
CR = 0x0D
RATE_POSITIONS = [9600, 19200, 38400, 57600, 115200]     # [R3] GVE54 rate jumpers
NUM = re.compile(r"^[0-9]{1,20}$")
SNUM = re.compile(r"^[+-]?[0-9]{1,20}$")
HEX = re.compile(r"^(?:[0-9A-Fa-f]{2})+$")


class ProtoError(Exception):
    pass


def num(s):
    if not NUM.match(s):
        raise ProtoError("bad number %r" % s)
    return int(s)


class Sim:
    def __init__(self, address="0", baud=115200):
        self.now = 0
        self.baud = baud
        self.b = round(1e10 / baud)
        self.rxq = deque()            # (instant, byte) host -> unit
        self.txq = deque()            # bytes waiting in the unit's transmitter
        self.tx_cur = None            # (instant of completion, byte)
        self.reported = []
        self.unit = Unit(self._send, address)

    # ------------------------------------------------------------ line
    def _mismatch(self):
        return self.unit.rate is not None and self.unit.rate != self.baud

    def _send(self, data, t):
        if self._mismatch():
            return                    # the host cannot read another rate
        self.txq.extend(data)
        if self.tx_cur is None:
            self._tx_start(t)

    def _tx_start(self, t):
        if self.txq:
            self.tx_cur = (t + self.b, self.txq.popleft())

    # ------------------------------------------------------------ clock
    def advance(self, limit, cr_rule):
        """Run the unit to `limit`; with cr_rule stop right after a CR to the
        host.  Returns True when stopped at a CR."""
        u = self.unit
        m = u.motion
        while True:
            t_rx = self.rxq[0][0] if self.rxq else INF
            t_tx = self.tx_cur[0] if self.tx_cur else INF
            t_u = u.next_timer()
            if t_u is None:
                t_u = INF
            t_o = min(t_rx, t_tx, t_u)
            ev = m.run_until(min(t_o, limit))
            if ev is not None:
                kind, t = ev
                self.now = max(self.now, t)
                u.on_motion(kind, t)
                continue
            if t_o > limit:
                self.now = limit
                return False
            self.now = t_o
            if t_u == t_o:
                u.on_timer(t_o)
                continue
            if t_tx == t_o:
                end, byte = self.tx_cur
                self.tx_cur = None
                self.reported.append((end, byte))
                self._tx_start(end)
                if byte == CR and cr_rule:
                    return True
                continue
            t, byte = self.rxq.popleft()
            if not self._mismatch():
                u.on_rx(t, byte)

    def next_event(self):
        c = []
        if self.rxq:
            c.append(self.rxq[0][0])
        if self.tx_cur:
            c.append(self.tx_cur[0])
        t = self.unit.next_timer()
        if t is not None:
            c.append(t)
        t = self.unit.motion.peek_event()
        if t is not None:
            c.append(t)
        return min(c) if c else None

    def take_rx_lines(self):
        out = []
        run = None
        for t, byte in self.reported:
            if run is not None and t == run[0] + len(run[1]) * self.b_at(run):
                run[1].append(byte)
            else:
                if run is not None:
                    out.append(run)
                run = [t, [byte]]
        if run is not None:
            out.append(run)
        self.reported = []
        return ["rx %d %s" % (t, bytes(bs).hex().upper()) for t, bs in out]

    def b_at(self, run):
        return self.b

    # ------------------------------------------------------------ commands
    def do_tx(self, hexstr, T=None):
        if not HEX.match(hexstr):
            raise ProtoError("bad hex %r" % hexstr)
        data = bytes.fromhex(hexstr)
        end = self.now + len(data) * self.b
        if T is not None and T < end:
            raise ProtoError("T before the end of the bytes")
        for i, byte in enumerate(data):
            self.rxq.append((self.now + (i + 1) * self.b, byte))
        n0 = len(self.reported)
        self.advance(end, False)
        crs = any(b == CR for _, b in self.reported[n0:])
        if T is not None and not crs:
            self.advance(T, True)
        return self.take_rx_lines() + ["now %d" % self.now]

    def command(self, line):
        """One command line -> list of reply lines (None: quit)."""
        w = line.split()
        if not w:
            return []
        cmd, args = w[0], w[1:]
        try:
            return self._dispatch(cmd, args)
        except ProtoError as e:
            return ["error: %s" % e]

    def _unit_arg(self, args):
        if args and args[-1].startswith("@"):
            a = args[-1][1:]
            if a.upper() != self.unit.address.upper() and \
                    not (a.isdigit() and self.unit.address.isdigit() and int(a) == int(self.unit.address)):
                raise ProtoError("no unit at address %s" % a)
            return args[:-1]
        return args

    def _dispatch(self, cmd, args):
        u = self.unit
        if cmd in ("quit", "exit"):
            return None
        if cmd == "help":
            return ["commands: tx HEX [T] | until T | next | baud N | batch D HEX ... | "
                    "in PORT HEX | switch AXIS POS|none | rate POS|none | power-on | state | quit"]
        if cmd == "tx":
            if len(args) not in (1, 2):
                raise ProtoError("tx HEX [T]")
            T = num(args[1]) if len(args) == 2 else None
            return self.do_tx(args[0], T)
        if cmd == "batch":
            if not args or len(args) % 2:
                raise ProtoError("batch D HEX [D HEX ...]")
            pairs = []
            for i in range(0, len(args), 2):
                d = num(args[i])
                if not HEX.match(args[i + 1]):
                    raise ProtoError("bad hex %r" % args[i + 1])
                pairs.append((d, args[i + 1]))
            out = []
            for d, h in pairs:
                end = self.now + (len(h) // 2) * self.b
                part = self.do_tx(h, end + d)
                out += part
                if not any(l.startswith("rx ") and self._has_cr(l) for l in part):
                    break                            # batch-stops
            return out
        if cmd == "until":
            if len(args) != 1:
                raise ProtoError("until T")
            T = num(args[0])
            if T < self.now:
                raise ProtoError("until before now")
            self.advance(T, True)
            return self.take_rx_lines() + ["now %d" % self.now]
        if cmd == "next":
            if args:
                raise ProtoError("next takes no argument")
            t = self.next_event()
            return ["next none" if t is None else "next %d" % max(t, self.now)]
        if cmd == "baud":
            if len(args) != 1:
                raise ProtoError("baud N")
            n = num(args[0])
            if n <= 0:
                raise ProtoError("bad rate")
            self.baud = n
            self.b = round(1e10 / n)
            return ["ok"]
        if cmd == "in":
            args = self._unit_arg(args)
            if len(args) != 2:
                raise ProtoError("in PORT XX")
            port = num(args[0])
            if port > 2 or not re.match(r"^[0-9A-Fa-f]{2}$", args[1]):
                raise ProtoError("in PORT(0-2) XX")
            u.set_input(port, int(args[1], 16), self.now)
            return ["ok"]
        if cmd == "switch":
            args = self._unit_arg(args)
            if len(args) != 2 or args[0] not in ("X", "Y", "Z", "A"):
                raise ProtoError("switch AXIS POS|none")
            if args[1] == "none":
                u.switches.pop(args[0], None)
            else:
                if not SNUM.match(args[1]):
                    raise ProtoError("bad position %r" % args[1])
                u.switches[args[0]] = int(args[1])   # GVE54 has no W: nothing sees it
            return ["ok"]
        if cmd == "rate":
            args = self._unit_arg(args)
            if len(args) != 1:
                raise ProtoError("rate POS|none")
            if args[0] == "none":
                u.rate_position = None
            else:
                p = num(args[0])
                if p >= len(RATE_POSITIONS):
                    raise ProtoError("rate position 0..%d" % (len(RATE_POSITIONS) - 1))
                u.rate_position = p
            return ["ok"]
        if cmd == "power-on":
            args = self._unit_arg(args)
            if args:
                raise ProtoError("power-on takes no argument")
            u.restart(self.now)
            u.rate = None if u.rate_position is None else RATE_POSITIONS[u.rate_position]
            return ["ok"]
        if cmd == "state":
            args = self._unit_arg(args)
            if args:
                raise ProtoError("state takes no argument")
            s = u.state()
            s["time_ns"] = self.now
            return [json.dumps(s)]
        raise ProtoError("unknown command %r" % cmd)

    @staticmethod
    def _has_cr(line):
        return "0D" in [line.split()[2][i:i + 2] for i in range(0, len(line.split()[2]), 2)]


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--cosim", action="store_true", help="co-simulation protocol (required)")
    ap.add_argument("--address", default="0", help="unit address character (jumpers), default 0")
    ap.add_argument("--baud", type=int, default=115200, help="initial line rate")
    a = ap.parse_args()
    if not a.cosim:
        sys.stderr.write("only --cosim (virtual time) is implemented\n")
        return 2
    sim = Sim(a.address, a.baud)
    out = sys.stdout
    out.write("cosim 1 batch batch-stops\n")
    out.flush()
    for raw in sys.stdin:
        line = raw.rstrip("\n").rstrip("\r")
        try:
            reply = sim.command(line)
        except Exception as e:                      # never die on the suite
            reply = ["error: internal: %s" % e]
        if reply is None:
            return 0
        if reply:
            out.write("\n".join(reply) + "\n")
            out.flush()
    return 0


if __name__ == "__main__":
    sys.exit(main())
