#!/usr/bin/env python3
"""GVE84 simulator -- co-simulation front end (given/cosim.md, given/rig.md).

    python3 sim.py --cosim [--model GVE84-15|GVE84-50|GVE84-100] [--eeprom FILE]

Virtual time only: the clock moves only with the commands on stdin.
"""
import argparse
import json
import re
import sys
from collections import deque

from unit import Unit, MODELS

NUM = re.compile(r"^[0-9]{1,20}$")
SNUM = re.compile(r"^[+-]?[0-9]{1,20}$")
HEXS = re.compile(r"^(?:[0-9A-Fa-f]{2})*$")


class ProtoError(Exception):
    pass


class CoSim:
    def __init__(self, model, eeprom=None, address=0):
        self.now = 0
        self.b = round(1e10 / 115200)
        self.to_unit = deque()          # (t, byte)
        self.to_host = []               # [t_end, byte], ordered
        self.unit = Unit(model, address=address, eeprom_path=eeprom, send=self._send)
        self.out_rx = []                # bytes reported during the current command

    # -------------------------------------------------- the unit's transmitter
    def _send(self, t, data):
        start = max(t, self.to_host[-1][0] if self.to_host else t)
        end = start
        for byte in data:
            end = end + self.b
            self.to_host.append([end, byte, t])
        return end

    # -------------------------------------------------- the clock
    def advance(self, limit, cr_stop):
        """Run to limit; returns True when stopped at a CR to the host."""
        u = self.unit
        for _guard in range(10_000_000):
            te = u.next_event()
            th = self.to_host[0][0] if self.to_host else None
            tu = self.to_unit[0][0] if self.to_unit else None
            cands = [x for x in (te, th, tu) if x is not None]
            if not cands:
                self.now = limit
                return False
            tmin = min(cands)
            if tmin > limit:
                self.now = limit
                return False
            tmin = max(tmin, self.now)
            self.now = tmin
            if te is not None and te <= tmin:
                u.process(tmin)
                continue
            if th is not None and th <= tmin:
                t, byte, _ = self.to_host.pop(0)
                self.out_rx.append((t, byte))
                if cr_stop and byte == 0x0D:
                    return True
                continue
            t, byte = self.to_unit.popleft()
            u.receive(t, byte)
        raise ProtoError("internal: event loop did not settle")

    def rx_lines(self):
        lines = ["rx %d %02X" % (t, b) for t, b in self.out_rx]
        self.out_rx = []
        return lines

    # -------------------------------------------------- commands
    def cmd_tx(self, hexs, T=None):
        data = bytes.fromhex(hexs)
        n = len(data)
        end = self.now + n * self.b
        if T is not None and T < end:
            raise ProtoError("T %d is before the bytes' end %d" % (T, end))
        for i, byte in enumerate(data):
            self.to_unit.append((self.now + (i + 1) * self.b, byte))
        self.advance(end, False)
        saw_cr = any(b == 0x0D for _, b in self.out_rx)
        if T is not None and not saw_cr:
            self.advance(T, True)
        return self.rx_lines() + ["now %d" % self.now]

    def cmd_until(self, T):
        if T < self.now:
            raise ProtoError("until %d is before now %d" % (T, self.now))
        self.advance(T, True)
        return self.rx_lines() + ["now %d" % self.now]

    def cmd_next(self):
        cands = [self.unit.next_event()]
        if self.to_host:
            cands.append(self.to_host[0][0])
        if self.to_unit:
            cands.append(self.to_unit[0][0])
        cands = [c for c in cands if c is not None]
        if not cands:
            return ["next none"]
        return ["next %d" % max(min(cands), self.now)]

    def cmd_baud(self, n):
        if n <= 0:
            raise ProtoError("bad baud rate")
        newb = round(1e10 / n)
        # a byte already begun keeps its instant; the rest take the new time
        prev_end = None
        for item in self.to_host:
            start = item[0] - self.b
            if start < self.now and prev_end is None:
                prev_end = item[0]
                continue
            st = max(item[2], self.now, prev_end if prev_end is not None else 0)
            item[0] = st + newb
            prev_end = item[0]
        self.b = newb
        return ["ok"]

    def handle(self, words):
        c = words[0]
        u = self.unit
        if c == "tx":
            if len(words) not in (2, 3) or not HEXS.match(words[1]) or not words[1]:
                raise ProtoError("usage: tx HEX [T]")
            T = None
            if len(words) == 3:
                T = self._num(words[2])
            return self.cmd_tx(words[1], T)
        if c == "until":
            if len(words) != 2:
                raise ProtoError("usage: until T")
            return self.cmd_until(self._num(words[1]))
        if c == "next":
            if len(words) != 1:
                raise ProtoError("usage: next")
            return self.cmd_next()
        if c == "baud":
            if len(words) != 2:
                raise ProtoError("usage: baud N")
            return self.cmd_baud(self._num(words[1]))
        if c == "batch":
            return self.cmd_batch(words[1:])
        # the rig
        words = self._strip_addr(words)
        c = words[0]
        if c == "state":
            if len(words) != 1:
                raise ProtoError("usage: state")
            u.process(self.now)
            return [json.dumps(u.state(self.now))]
        if c == "in":
            if len(words) != 3 or not NUM.match(words[1]) or not re.match(r"^[0-9A-Fa-f]{2}$", words[2]):
                raise ProtoError("usage: in PORT XX")
            port = int(words[1])
            if port > 2:
                raise ProtoError("no input port %d" % port)
            u.process(self.now)
            u.set_input(self.now, port, int(words[2], 16))
            return ["ok"]
        if c == "switch":
            if len(words) != 3:
                raise ProtoError("usage: switch AXIS POS|none")
            ax = {"X": 0, "Y": 1, "Z": 2}.get(words[1].upper())
            if ax is None:
                raise ProtoError("no axis %s on a GVE84" % words[1])
            if words[2] == "none":
                u.switches.pop(ax, None)
            else:
                if not SNUM.match(words[2]):
                    raise ProtoError("bad position")
                u.switches[ax] = int(words[2])
            return ["ok"]
        if c == "power-on":
            if len(words) != 1:
                raise ProtoError("usage: power-on")
            u.process(self.now)
            u.power_on(self.now)
            return ["ok"]
        if c == "rate":
            raise ProtoError("the GVE84's rate is fixed at order time")
        if c == "help":
            return ["commands: tx HEX [T] | until T | next | baud N | batch D HEX ... | "
                    "in PORT XX | switch AXIS POS|none | power-on | state | quit"]
        raise ProtoError("unknown command '%s'" % c)

    def cmd_batch(self, args):
        if not args or len(args) % 2:
            raise ProtoError("usage: batch D HEX [D HEX ...]")
        pairs = []
        for i in range(0, len(args), 2):
            if not HEXS.match(args[i + 1]) or not args[i + 1]:
                raise ProtoError("bad hex")
            pairs.append((self._num(args[i]), args[i + 1]))
        out = []
        for d, hexs in pairs:
            end = self.now + (len(hexs) // 2) * self.b
            lines = self.cmd_tx(hexs, end + d)
            out.extend(lines)
            if not any(l.startswith("rx ") and l.endswith("0D") for l in lines):
                break
        return out

    def _strip_addr(self, words):
        if len(words) > 1 and words[-1].startswith("@"):
            a = words[-1][1:]
            if not NUM.match(a) or int(a) != self.unit.address:
                raise ProtoError("no unit at address %s" % a)
            words = words[:-1]
        return words

    @staticmethod
    def _num(s):
        if not NUM.match(s):
            raise ProtoError("bad number '%s'" % s)
        return int(s)


def run_cosim(args):
    sim = CoSim(args.model, eeprom=args.eeprom, address=args.address)
    out = sys.stdout
    out.write("cosim 1 batch batch-stops\n")
    out.flush()
    for line in sys.stdin:
        line = line.rstrip("\n").rstrip("\r")
        words = line.split()
        if not words:
            continue
        if words[0] in ("quit", "exit") and len(words) == 1:
            break
        try:
            replies = sim.handle(words)
        except ProtoError as e:
            replies = ["error: %s" % e]
        except Exception as e:          # never die: report and go on
            replies = ["error: internal: %r" % (e,)]
            print("internal error: %r" % (e,), file=sys.stderr)
        out.write("\n".join(replies) + "\n")
        out.flush()
    return 0


def main():
    ap = argparse.ArgumentParser(description="GVE84 interpolator simulator")
    ap.add_argument("--cosim", action="store_true", help="speak the co-simulation protocol on stdin/stdout")
    ap.add_argument("--model", default="GVE84-100", choices=sorted(MODELS))
    ap.add_argument("--eeprom", default=None, help="EEPROM image file (256 bytes), kept across runs")
    ap.add_argument("--address", type=int, default=0, choices=range(8), help="unit address 0-7 (12.5)")
    args = ap.parse_args()
    if not args.cosim:
        ap.error("only --cosim mode is implemented")
    sys.exit(run_cosim(args))


if __name__ == "__main__":
    main()
