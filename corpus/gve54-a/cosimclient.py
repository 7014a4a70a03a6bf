"""A small driver of `sim.py --cosim` through its stdin/stdout, as the suite
drives it: one frame at a time, each answer awaited up to its CR."""

import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))


class CosimClient:
    def __init__(self, *args):
        self.p = subprocess.Popen([sys.executable, os.path.join(HERE, "sim.py"), "--cosim", *args],
                                  stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, bufsize=1)
        first = self.p.stdout.readline().split()
        assert first[:2] == ["cosim", "1"], first
        self.now = 0
        assert self.cmd("baud 115200") == ["ok"]

    def cmd(self, line):
        """Send one protocol line; return the reply lines (up to the final one)."""
        self.p.stdin.write(line + "\n")
        self.p.stdin.flush()
        out = []
        while True:
            l = self.p.stdout.readline()
            if not l:
                raise RuntimeError("simulator ended after %r" % line)
            l = l.rstrip("\n")
            out.append(l)
            if not l.startswith("rx "):
                if l.startswith("now "):
                    self.now = int(l.split()[1])
                return out

    def frame(self, text, wait_ns=1_000_000_000):
        """Send `text` + CR; return the answer text (without CR) or None."""
        data = (text + "\r").encode("latin-1")
        end = self.now + len(data) * 86806
        reply = self.cmd("tx %s %d" % (data.hex().upper(), end + wait_ns))
        got = bytearray()
        for l in reply:
            if l.startswith("rx "):
                got += bytes.fromhex(l.split()[2])
        if not got:
            return None
        assert got.endswith(b"\r"), got
        return got[:-1].decode("latin-1")

    def until(self, t):
        reply = self.cmd("until %d" % t)
        return reply

    def wait(self, ns):
        return self.until(self.now + ns)

    def close(self):
        try:
            self.p.stdin.write("quit\n")
            self.p.stdin.flush()
        except BrokenPipeError:
            pass
        self.p.wait(timeout=10)
