"""A small driver for sim.py --cosim (used by selftest.py)."""
import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))


class Sim:
    def __init__(self, *args):
        self.p = subprocess.Popen([sys.executable, os.path.join(HERE, 'sim.py'), '--cosim', *args],
                                  stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
        first = self.p.stdout.readline().split()
        assert first[:2] == ['cosim', '1'], first
        self.now = 0
        self.b = 86806
        assert self.cmd('baud 115200') == ['ok']
        self.state()

    def cmd(self, line):
        """Send one command, return its reply lines (up to and including the final one)."""
        self.p.stdin.write(line + '\n')
        self.p.stdin.flush()
        out = []
        while True:
            r = self.p.stdout.readline()
            if not r:
                raise RuntimeError('simulator ended after %r' % line)
            r = r.rstrip('\n')
            out.append(r)
            if not r.startswith('rx '):
                if r.startswith('now '):
                    t = int(r.split()[1])
                    assert t >= self.now, 'time went backwards'
                    self.now = t
                return out

    @staticmethod
    def rx_text(lines):
        s = b''
        for ln in lines:
            if ln.startswith('rx '):
                s += bytes.fromhex(ln.split()[2])
        return s.decode('latin-1')

    def frame(self, text, wait_ns=1_000_000_000):
        """Send text (a '\\r' is added) and wait up to wait_ns after it for a CR.
        Returns the answer without its CR, or None when nothing came."""
        data = (text + '\r').encode('latin-1')
        T = self.now + len(data) * self.b + wait_ns
        lines = self.cmd('tx %s %d' % (data.hex().upper(), T))
        ans = self.rx_text(lines)
        if not ans:
            return None
        assert ans.endswith('\r'), repr(ans)
        return ans[:-1]

    def raw(self, data):
        return self.rx_text(self.cmd('tx %s' % data.hex().upper()))

    def until(self, t):
        return self.rx_text(self.cmd('until %d' % t))

    def wait_ms(self, ms):
        return self.until(self.now + int(ms * 1_000_000))

    def next(self):
        r = self.cmd('next')[0].split()
        return None if r[1] == 'none' else int(r[1])

    def state(self):
        return json.loads(self.cmd('state')[0])

    def rig(self, line):
        r = self.cmd(line)
        assert r == ['ok'], r

    def close(self):
        try:
            self.p.stdin.write('quit\n')
            self.p.stdin.flush()
        except BrokenPipeError:
            pass
        self.p.wait(5)
