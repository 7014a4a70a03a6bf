#!/usr/bin/env python3
"""Self-test: the GVE114 manual's worked examples, run against sim.py --cosim.

Every example exchange of the manual is sent through the co-simulation
protocol (tx HEX T) and the documented answer is asserted.  One line per
example; exit status 0 when all pass.
"""
import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
SEC = 1_000_000_000


class Sim:
    def __init__(self, *extra):
        self.p = subprocess.Popen([sys.executable, os.path.join(HERE, 'sim.py'), '--cosim',
                                   *extra], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                  text=True, bufsize=1)
        first = self.p.stdout.readline().split()
        assert first[:2] == ['cosim', '1'], first
        self.now = 0
        self.b = None
        assert self.cmd('baud 115200') == ['ok']
        self.b = round(1e10 / 115200)

    def cmd(self, line):
        self.p.stdin.write(line + '\n')
        self.p.stdin.flush()
        out = []
        while True:
            r = self.p.stdout.readline()
            if not r:
                raise RuntimeError('simulator ended')
            r = r.rstrip('\n')
            out.append(r)
            if not r.startswith('rx '):
                if r.startswith('now '):
                    self.now = int(r.split()[1])
                return out

    def tx(self, text, wait=SEC):
        """Send one frame (text without CR); return (answer text, instants)."""
        data = (text + '\r').encode('latin-1')
        end = self.now + len(data) * self.b
        lines = self.cmd('tx %s %d' % (data.hex().upper(), end + wait))
        assert lines[-1].startswith('now '), lines
        got = b''
        times = []
        for l in lines[:-1]:
            _, t, hx = l.split()
            got += bytes.fromhex(hx)
            times.append(int(t))
        return got.decode('latin-1'), times

    def ask(self, text, wait=SEC):
        return self.tx(text, wait)[0]

    def batch(self, line):
        """A batch reply has one `now` per frame run: read up to a `next` sentinel."""
        self.p.stdin.write(line + '\nnext\n')
        self.p.stdin.flush()
        out = []
        while True:
            r = self.p.stdout.readline().rstrip('\n')
            if r.startswith('next'):
                return out
            out.append(r)
            if r.startswith('now '):
                self.now = int(r.split()[1])

    def state(self):
        return json.loads(self.cmd('state')[0])

    def until(self, t):
        return self.cmd('until %d' % t)

    def close(self):
        self.p.stdin.write('quit\n')
        self.p.stdin.flush()
        self.p.wait(5)


RESULTS = []


def check(name, cond, detail=''):
    RESULTS.append(bool(cond))
    print('%s  %s%s' % ('PASS' if cond else 'FAIL', name, '' if cond else '   ' + detail))


def expect(sim, name, frame, answer, wait=SEC):
    got = sim.ask(frame, wait)
    check('%s: %s -> %r' % (name, frame, answer), got == answer, 'got %r' % got)
    return got


def main():
    # ---------------------------------------------------------------- 13.3.2
    s = Sim()
    expect(s, '13.3.2 checksum on', '!0%+', '0,5C\r')
    expect(s, '13.3.2 summed frame', '!0A100,4F', '0,5C\r')
    expect(s, '13.3.2 bad sum refused', '!0A100,4E', '4,60\r')
    expect(s, '13.3.2 checksum off', '!0%-,CF', '0\r')
    expect(s, '13.3.2 plain again', '!0A100', '0\r')
    s.close()

    # ---------------------------------------------------------------- 13.4 packet
    s = Sim()
    expect(s, '13.4 checksums on', '!0%+', '0,5C\r')
    got = s.ask('!0*S,FA', wait=1_000_000)
    check('13.4 packet start !0*S,FA: no answer', got == '', 'got %r' % got)
    vecs = ['!0C697,30,0,51', '!0C692,92,0,54', '!0C682,151,0,7F', '!0C665,209,0,84',
            '!0C645,268,0,87', '!0C619,322,0,7F', '!0C589,375,0,8D', '!0C553,425,0,80',
            '!0C515,471,0,7F', '!0C471,515,0,7F']
    silent = all(s.ask(v, wait=100_000) == '' for v in vecs)
    check('13.4 packet vectors (10 x C): no answers', silent)
    expect(s, '13.4 packet end', '!0*E10,4D', '0,10,E9\r')
    st = s.state()
    check('13.4 the 10 vectors run as one CONT chain', st['status'][6] == '40' and st['queue'] >= 1,
          str(st['status']))
    s.close()

    # ---------------------------------------------------------------- 13.5 reset
    s = Sim()
    expect(s, '13.5 J (jump to reset)', '!0J', '0\r')
    t_j = s.now
    got = s.ask('!0SR6', wait=100_000_000)
    check('13.5 deaf for about 2 s after J', got == '', 'got %r' % got)
    s.until(t_j + 2 * SEC + 1)
    ok = all(s.ask('!0SR%d' % n) == '0,00\r' for n in range(7))
    check('13.5 ST0..ST6 = 00 after reset', ok)
    st = s.state()
    m = st['modal']
    check('13.5 A20 V1000 $512 B(max) N O0,FF',
          m['A'] == 20 and m['V'] == 1000 and m['$'] == 512 and m['B'] == 500000
          and st['position'] == [0, 0, 0, 0] and st['outputs'] == 'FF', str(st))
    s.close()

    # ---------------------------------------------------------------- 13.6.1
    s = Sim()
    expect(s, '13.6.1 version (13.2)', '!0?', '0,IP114/500 x16 16.9.2018\r')
    got = s.ask('!0Q')
    check('13.6.1 Q answers 8 digits ddmmrrpp', got.startswith('0,') and len(got) == 11
          and got[2:10].isdigit(), repr(got))
    s.close()

    # ---------------------------------------------------------------- 13.6.2 .. 13.6.5
    s = Sim()
    expect(s, '13.6.3 A', '!0A50', '0\r')
    expect(s, '13.6.3 V', '!0V10000', '0\r')
    expect(s, '13.6.3 VL', '!0VL25000,25000,30000', '0\r')
    expect(s, '13.6.3 B', '!0B5000', '0\r')
    expect(s, '13.6.2 T', '!0T5', '0\r')
    expect(s, '13.6.2 $', '!0$512', '0\r')
    expect(s, '13.6.4 VK', '!0VK', '0\r')
    expect(s, '13.6.4 VN', '!0VN', '0\r')
    expect(s, '13.6.2 L vector', '!0L1000,1000,20', '0\r')
    expect(s, '13.6.2 C vector', '!0C1000,1000,20', '0\r')
    expect(s, '13.6.2 L0,0,0 while the queue runs', '!0L0,0,0', '1\r')
    expect(s, '13.6.5 XU', '!0XU', '0\r')
    expect(s, '13.6.5 XD', '!0XD', '0\r')
    expect(s, '13.6.5 XA', '!0XA', '0\r')
    expect(s, '13.6.5 XM100', '!0XM100', '0\r')
    expect(s, '13.6.5 XM200', '!0XM200', '0\r')
    got = s.ask('!0F')
    check('13.6.12 F while running: RUN=1', got == '0,40\r', repr(got))
    s.until(s.now + 2 * SEC)
    expect(s, '13.6.2 L0,0,0 once the queue is done', '!0L0,0,0', '0\r')
    s.until(s.now + 100_000_000)
    expect(s, '13.6.6 PF after L+C', '!0PF', '0,2000,2000,40\r')
    expect(s, '13.6.6 P', '!0P', '0,2000,2000\r')
    s.close()

    # ---------------------------------------------------------------- 13.6.6
    s = Sim()
    expect(s, '13.6.6 NX0', '!0NX0', '0\r')
    expect(s, '13.6.6 NX100', '!0NX100', '0\r')
    expect(s, '13.6.6 PF', '!0PF', '0,100,0,0\r')
    expect(s, '13.6.6 N', '!0N', '0\r')
    expect(s, '13.6.6 PF after N', '!0PF', '0,0,0,0\r')
    s.close()

    # ---------------------------------------------------------------- 13.6.7 W
    s = Sim()
    s.cmd('switch Y -1500')
    ans, times = s.tx('!0WY-20000,1000,2000,500', wait=3 * SEC)
    check('13.6.7 !0WY-20000,1000,2000,500 answers 0 after the run', ans == '0\r', repr(ans))
    st = s.state()
    check('13.6.7 Y zeroed one step back from the switch', st['position'][1] == 0 and
          st['physical'][1] == -1499, str(st['position']) + str(st['physical']))
    s.close()

    # ---------------------------------------------------------------- 13.6.9 KEEP / RESTORE
    s = Sim()
    s.ask('!0V1000')
    s.ask('!0L20000,0,0')
    s.ask('!0C0,20000,0')
    s.until(s.now + 500_000_000)
    expect(s, '13.6.9 !0H stops the vector', '!0H', '8\r')
    got = s.ask('!0P')
    check('13.6.9 !0P where we stopped', got.startswith('8,') and got.count(',') == 2, repr(got))
    expect(s, '13.6.9 !0SR4', '!0SR4', '8,00\r')
    expect(s, '13.6.9 !0SR5', '!0SR5', '8,00\r')
    expect(s, '13.6.9 !0SR6 (INTA RUN INTCOM)', '!0SR6', '8,D0\r')
    expect(s, '13.6.9 !0SW0,1A', '!0SW0,1A', '8\r')
    expect(s, '13.6.9 !0SW1,3F', '!0SW1,3F', '8\r')
    expect(s, '13.6.9 !0K', '!0K', '0\r')
    expect(s, '13.6.9 !0L0,0,-1000', '!0L0,0,-1000', '0\r')
    s.until(s.now + 2 * SEC)
    expect(s, '13.6.9 !0L0,0,1000', '!0L0,0,1000', '0\r')
    s.until(s.now + 2 * SEC)
    expect(s, '13.6.9 !0R', '!0R', '8\r')
    expect(s, '13.6.9 !0V500', '!0V500', '8\r')
    expect(s, '13.6.9 !0XA', '!0XA', '8\r')
    expect(s, '13.6.9 !0SW0,A2', '!0SW0,A2', '8\r')
    expect(s, '13.6.9 !0SW1,78', '!0SW1,78', '8\r')
    expect(s, '13.6.9 !0G', '!0G', '0\r')
    got = s.ask('!0SR6')
    check('13.6.9 running again after G', got == '0,40\r', repr(got))
    s.close()

    # ---------------------------------------------------------------- 13.6.9 H/D/G
    s = Sim()
    expect(s, '13.6.9 G with nothing to go', '!0G', '6\r')
    expect(s, '13.6.9 H at rest', '!0H', '8\r')
    expect(s, '13.6.9 D', '!0D', '0\r')
    s.close()

    # ---------------------------------------------------------------- 13.6.10 EEPROM
    s = Sim()
    expect(s, '11.5 default 0x05 = FF', '!0ER05', '0,FF\r')
    expect(s, '11.5 EW05,AC', '!0EW05,AC', '0\r')
    expect(s, '11.5 ER05', '!0ER05', '0,AC\r')
    expect(s, '12.9 EFW60,0.1', '!0EFW60,0.1', '0\r')
    expect(s, '12.9 EFR60', '!0EFR60', '0,0.1\r')
    expect(s, '12.8 EUW4C,500', '!0EUW4C,500', '0\r')
    expect(s, '12.8 EUR4C', '!0EUR4C', '0,500\r')
    s.close()

    # ---------------------------------------------------------------- 13.6.11 outputs
    s = Sim()
    expect(s, '13.6.11 cooling on !0O0,FB', '!0O0,FB', '0\r')
    check('13.6.11 outputs read FB', s.state()['outputs'] == 'FB')
    expect(s, '13.6.11 all off !0O0,FF', '!0O0,FF', '0\r')
    check('13.6.11 outputs read FF', s.state()['outputs'] == 'FF')
    s.close()

    # ---------------------------------------------------------------- 13.6.12 inputs
    s = Sim()
    s.cmd('in 1 FE')
    expect(s, '13.6.12 I1', '!0I1', '0,FE\r')
    expect(s, '13.6.12 I2', '!0I2', '0,FF\r')
    s.close()

    # ---------------------------------------------------------------- 13.6.13
    s = Sim()
    s.ask('!0SR6')
    s.ask('!0SR6')
    expect(s, '13.6.13 @ index', '!0@', '0,2\r')
    expect(s, '13.6.13 > repeat', '!0>', '0,2\r')
    s.close()

    # ---------------------------------------------------------------- 13.7 spindle
    s = Sim()
    expect(s, '13.7 !7V300', '!7V300', '0\r')
    st = s.state()
    check('13.7 spindle 300 per mille, OUT0 on', st['spindle'] == 300 and st['outputs'] == 'FE',
          str(st['spindle']) + st['outputs'])
    expect(s, '13.7 !7V0', '!7V0', '0\r')
    st = s.state()
    check('13.7 !7V0 switches OUT0 off', st['spindle'] == 0 and st['outputs'] == 'FF')
    expect(s, '13.7 ? at address 7', '!7?', '0,IP114/500 x16 16.9.2018\r')
    expect(s, '13.7 L refused at address 7', '!7L1,0,0', '3\r')
    s.close()

    # ---------------------------------------------------------------- 13.8 table
    s = Sim()
    expect(s, '13.8 !0L1000,0,0', '!0L1000,0,0', '0\r')
    s.until(s.now + 2 * SEC)
    s.ask('!0NX-1000')
    s.ask('!0NY2000')
    s.ask('!0NZ50')
    expect(s, '13.8 !0PF', '!0PF', '0,-1000,2000,50\r')
    expect(s, '13.8 !0SW8,F1', '!0SW8,F1', '5\r')
    s.ask('!0SW2,2B')
    expect(s, '13.8 !0SR2', '!0SR2', '0,2B\r')
    s.ask('!0V10')
    s.ask('!0L1000,0,0')
    frames = ' '.join('200000 ' + ('!0C100,20,0\r').encode().hex().upper() for _ in range(2047))
    lines = s.batch('batch ' + frames)
    check('13.6.2 2047 C vectors queued behind the L', sum(l == 'rx %s 300D' % l.split()[1] for l in lines if l.startswith('rx')) == 2047)
    expect(s, '13.8 !0C100,20,0 with the queue full', '!0C100,20,0', '1\r')
    got = s.ask('!0F')
    check('13.6.12 F bit 5: queue full', got == '0,60\r', repr(got))
    expect(s, '13.8 H', '!0H', '8\r', wait=SEC)
    expect(s, '13.8 !0V1000 while interrupted', '!0V1000', '8\r')
    s.close()

    # ---------------------------------------------------------------- 10.1 rate switch
    s = Sim()
    s.cmd('rate 0')
    s.cmd('power-on')
    s.until(s.now + 2 * SEC)
    got = s.ask('!0SR6', wait=10_000_000)
    check('10.1 sw1 OFF sw2 OFF, 0x0D=FF: 19200 Bd (115200 unheard)', got == '', repr(got))
    s.cmd('baud 19200')
    s.b = round(1e10 / 19200)
    expect(s, '10.1 heard at 19200 Bd', '!0SR6', '0,00\r')
    s.close()


    # ---------------------------------------------------------------- 13.7 !7V500 vs !0V500
    s = Sim()
    expect(s, '13.7 !0V500 (speed, not spindle)', '!0V500', '0\r')
    st = s.state()
    check('13.7 !0V500 sets V, spindle untouched', st['modal']['V'] == 500 and st['spindle'] == 0)
    expect(s, '13.7 !7V500', '!7V500', '0\r')
    st = s.state()
    check('13.7 !7V500 sets the spindle to 500 (5 V), V untouched',
          st['modal']['V'] == 500 and st['spindle'] == 500 and st['outputs'] == 'FE')
    s.close()

    # ---------------------------------------------------------------- 11.5 STEP/DIR 0xAC
    s = Sim()
    expect(s, '11.5 !0EW05,AC', '!0EW05,AC', '0\r')
    expect(s, '11.5 J (read at reset)', '!0J', '0\r')
    s.until(s.now + 2 * SEC + 1)
    expect(s, '11.5 L100,100,100,100', '!0L100,100,100,100', '0\r')
    s.until(s.now + 2 * SEC)
    st = s.state()
    check('11.5 0xAC: X reversed, Y normal, Z reversed, A normal',
          st['position'] == [100, 100, 100, 100] and st['physical'] == [-100, 100, -100, 100],
          str(st['physical']))
    s.close()

    # ---------------------------------------------------------------- 11.2 brake after FD
    s = Sim()
    expect(s, '11.2 OUT3 = brake (08)', '!0EW03,08', '0\r')
    expect(s, '11.1 FD = 10 x 0.1 s', '!0EWFD,0A', '0\r')
    s.cmd('power-on')
    t0 = s.now
    s.until(t0 + 900_000_000)
    a = s.state()['outputs']
    s.until(t0 + 1_000_000_000)
    b = s.state()['outputs']
    check('11.2 brake output (OUT3, bit 1) on 1.0 s after power-on', a == 'FF' and b == 'FD',
          a + ' ' + b)
    s.close()

    # ---------------------------------------------------------------- 10.1 0x0D = 01
    s = Sim()
    expect(s, '10.1 !0EW0D,01', '!0EW0D,01', '0\r')
    s.cmd('rate 1')
    s.cmd('power-on')
    s.until(s.now + 2 * SEC)
    s.cmd('baud 460800')
    s.b = round(1e10 / 460800)
    expect(s, '10.1 0x0D=01, sw1 OFF sw2 ON: 460 800 Bd', '!0SR6', '0,00\r')
    check('10.1 state.rate', s.state()['rate'] == 460800)
    s.close()

    n = len(RESULTS)
    bad = RESULTS.count(False)
    print('%d of %d checks passed' % (n - bad, n))
    return 1 if bad else 0


if __name__ == '__main__':
    sys.exit(main())
