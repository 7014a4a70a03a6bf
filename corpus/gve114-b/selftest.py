#!/usr/bin/env python3
"""Runs the manual's worked examples against sim.py through the cosim protocol
(given/cosim.md) and asserts the documented answers.  Exit status 0 = all pass.

Each check names the manual section it comes from.  Where the manual shows an
answer, that answer is asserted verbatim; where it only shows the command, the
check asserts the behaviour the manual describes (and READINGS.md fixes).
"""
import json
import os
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
FINAL = re.compile(r'^(now \d+|next (\d+|none)|ok|\{.*\}|error: .*)$')

failures = []
passes = 0


def check(cond, what):
    global passes
    if cond:
        passes += 1
        print('PASS', what)
    else:
        failures.append(what)
        print('FAIL', what)


class Sim:
    def __init__(self, model='GVE114-500'):
        self.p = subprocess.Popen([sys.executable, os.path.join(HERE, 'sim.py'), '--cosim',
                                   '--model', model],
                                  stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, bufsize=1)
        self.first = self.p.stdout.readline().strip()
        self.now = 0

    def cmd(self, line):
        self.p.stdin.write(line + '\n')
        self.p.stdin.flush()
        lines = []
        while True:
            ln = self.p.stdout.readline()
            if not ln:
                raise RuntimeError('simulator ended after %r' % line)
            ln = ln.rstrip('\n')
            lines.append(ln)
            if FINAL.match(ln):
                break
        m = re.match(r'now (\d+)', lines[-1])
        if m:
            self.now = int(m.group(1))
        return lines

    @staticmethod
    def rx_text(lines):
        return ''.join(chr(int(l.split()[2], 16)) for l in lines if l.startswith('rx '))

    def ask(self, text, wait_ns=1_000_000_000):
        """Send one frame (CR added) and wait for its answer; returns the
        answer without its CR, or None when nothing came within wait_ns."""
        hexs = (text + '\r').encode('latin-1').hex().upper()
        end = self.now + len(hexs) // 2 * round(1e10 / self.baud) + wait_ns
        got = self.rx_text(self.cmd('tx %s %d' % (hexs, end)))
        if got.endswith('\r'):
            return got[:-1]
        return None if not got else got

    def send_only(self, text):
        hexs = (text).encode('latin-1').hex().upper()
        return self.rx_text(self.cmd('tx %s' % hexs))

    def until(self, t):
        return self.rx_text(self.cmd('until %d' % t))

    def wait(self, ns):
        return self.until(self.now + ns)

    def state(self):
        return json.loads(self.cmd('state')[-1])

    baud = 115200

    def idle(self, limit_s=60):
        """Poll F until RUN=0 (the host's way of waiting for the queue)."""
        for _ in range(limit_s * 10):
            a = self.ask('!0F')
            if a and int(a.split(',')[1], 16) & 0x40 == 0:
                return a
            self.wait(100_000_000)
        return None

    def close(self):
        try:
            self.p.stdin.write('quit\n')
            self.p.stdin.flush()
            self.p.wait(5)
        except Exception:
            self.p.kill()


def cs(s):
    """13.3.2: append ',' and the modulo-256 sum of every character."""
    s += ','
    return s + '%02X' % (sum(s.encode()) & 0xFF)


def main():
    s = Sim()
    check(s.first == 'cosim 1', 'cosim handshake first line "cosim 1"')
    check(s.cmd('baud 115200') == ['ok'], 'cosim baud')
    st = s.state()
    check(st['profile'] == 'GVE114-500' and 'spindle' in st and st['status'] == ['00'] * 7,
          'rig state JSON (profile, spindle, status)')

    # 13.6.1 identification
    a = s.ask('!0?')
    check(a == '0,IP114/500 x16 16.9.2018', '13.6.1/13.2 ? -> version (%r)' % a)
    a = s.ask('!0Q')
    check(a is not None and re.fullmatch(r'0,\d{8}', a), '13.6.1 Q -> 8 digits ddmmrrpp (%r)' % a)

    # 13.3.2 checksums
    check(cs('!0A100') == '!0A100,4F', '13.3.2 worked sum !0A100 -> !0A100,4F')
    check(s.ask('!0%+') == '0,5C', '13.3.2 !0%+ -> 0,5C')
    check(s.ask('!0A100,4F') == '0,5C', '13.3.2 !0A100,4F accepted with checksums on')
    a = s.ask('!0A100,4E')
    check(a is not None and a.startswith('4,'), '13.3.2 wrong sum refused (%r)' % a)
    check(s.ask('!0%-,CF') == '0', '13.3.2 !0%-,CF -> 0')
    check(s.ask('!0A20') == '0', 'checksums off again')

    # 13.4 packet, exactly as printed (all sums verified)
    check(s.ask('!0%+') == '0,5C', '13.4 checksums on for the packet')
    pk = ['!0*S,FA', '!0C697,30,0,51', '!0C692,92,0,54', '!0C682,151,0,7F', '!0C665,209,0,84',
          '!0C645,268,0,87', '!0C619,322,0,7F', '!0C589,375,0,8D', '!0C553,425,0,80',
          '!0C515,471,0,7F', '!0C471,515,0,7F']
    for f in pk:
        check(s.send_only(f + '\r') == '', '13.4 no answer inside the packet: %s' % f)
    check(s.ask('!0*E10,4D') == '0,10,E9', '13.4 !0*E10,4D -> 0,10,E9')
    check(s.ask('!0%-,CF') == '0', '13.4 checksums off')
    s.idle()
    a = s.ask('!0PF')
    check(a == '0,6128,2858,0', '13.4 packet path ends at the sum of its vectors (%r)' % a)

    # 13.6.6 N / Nan
    check(s.ask('!0N') == '0', '13.6.6 N')
    check(s.ask('!0NX100') == '0' and s.ask('!0PF') == '0,100,0,0', '13.6.6 !0NX100 sets X to 100')
    check(s.ask('!0NX0') == '0' and s.ask('!0PF') == '0,0,0,0', '13.6.6 !0NX0 zeroes X')

    # 13.6.2 vectors, L0,0,0 trick, T, $
    check(s.ask('!0T5') == '0', '13.6.2 !0T5')
    check(s.ask('!0T25') == '5', '13.6.2 T outside 1..24 -> 5')
    check(s.ask('!0L1000,1000,20') == '0', '13.6.2 !0L1000,1000,20 accepted')
    a = s.ask('!0P')
    check(a is not None and a.startswith('0,'), '13.6.6 P while moving (%r)' % a)
    check(s.ask('!0L0,0,0') == '1', '13.6.2 L0,0,0 while the queue runs -> 1')
    for _ in range(100):
        a = s.ask('!0L0,0,0')
        if a != '1':
            break
        s.wait(50_000_000)
    check(a == '0', '13.6.2 L0,0,0 -> 0 once the queue before it is done')
    check(s.ask('!0PF') == '0,1000,1000,20', '13.6.2 relative vector reached (1000,1000,20)')
    check(s.ask('!0N') == '0', 'N after the move')
    check(s.ask('!0C1000,1000,20') == '0', '13.6.2 !0C1000,1000,20 accepted')
    check(s.ask('!0$512') == '0', '13.6.2 $ (short vector limit)')
    check(s.ask('!0$0') == '5', '13.6.2 $0 out of range -> 5')
    s.idle()

    # 13.6.3 / 13.6.4 / 13.6.5 speeds
    check(s.ask('!0A50') == '0', '13.6.3 !0A50')
    check(s.ask('!0V10000') == '0', '13.6.3 !0V10000')
    check(s.ask('!0V5') == '5', '13.6.3 V below 10 -> 5')
    check(s.ask('!0VL25000,25000,30000') == '0', '13.6.3 !0VL25000,25000,30000')
    check(s.ask('!0B5000') == '0', '13.6.3 B')
    check(s.ask('!0VK') == '0' and s.ask('!0VN') == '0', '13.6.4 VK, VN')
    check(s.ask('!0XM100') == '0' and s.ask('!0XM200') == '0', '13.6.5 !0XM100, !0XM200')
    for c in ('XA', 'XU', 'XD', 'XM100'):
        check(s.ask('!0' + c) == '0', '13.6.5 ' + c)
    # timing: V10000 A50: 20000 steps take ~2.2 s; with XM200 ~1.2 s
    check(s.ask('!0N') == '0', 'N')
    t0 = s.now
    check(s.ask('!0L20000,0,0') == '0', 'L20000 at V10000 A50')
    s.idle()
    dt1 = s.now - t0
    check(1_900_000_000 < dt1 < 2_500_000_000, 'motion is simulated in time (%.3f s)' % (dt1 / 1e9))

    # 13.8 response table
    check(s.ask('!0V1000') == '0' and s.ask('!0A20') == '0', 'back to reset speeds')
    check(s.ask('!0N') == '0', 'N')
    check(s.ask('!0L1000,0,0') == '0', '13.8 !0L1000,0,0 -> 0')
    s.idle()
    s.ask('!0NX-1000')
    s.ask('!0NY2000')
    s.ask('!0NZ50')
    check(s.ask('!0PF') == '0,-1000,2000,50', '13.8 !0PF -> 0,-1000,2000,50')
    check(s.ask('!0V10') == '0', 'slow V to fill the queue')
    for i in range(2048):
        a = s.ask('!0C100000,0,0')
        if a != '0':
            break
    check(i == 2047 and a == '0', '13.6.2 the queue holds 2048 vectors')
    check(s.ask('!0C100,20,0') == '1', '13.8 !0C100,20,0 -> 1 (queue full)')
    a = s.ask('!0F')
    check(a == '0,60', '13.6.12 F: RUN and queue-full bit 5 (%r)' % a)
    a = s.ask('!0H', 5_000_000_000)
    check(a == '8', '13.6.9 H answers 8 once stopped (%r)' % a)
    check(s.ask('!0V1000') == '8', '13.8 !0V1000 -> 8 (OK, but interrupted INTA=1)')
    check(s.ask('!0SR6') == '8,D0', '13.6.12 SR6 after H: INTA RUN INTCOM (D0)')
    check(s.ask('!0D') == '0', '13.6.9 D clears the queue and flags')
    check(s.ask('!0SW8,F1') == '5', '13.8 !0SW8,F1 -> 5')
    check(s.ask('!0SW2,2B') == '0', 'SW2,2B')
    check(s.ask('!0SR2') == '0,2B', '13.8 !0SR2 -> 0,2B')
    check(s.ask('!0SW2,00') == '0', 'SW2,00')
    check(s.ask('!0G') == '6', '13.8 G with nothing to start -> 6')
    check(s.ask('!0Z') == '3', '13.8 unknown command -> 3')
    check(s.ask('!0L1,x,3') == '4', '13.8 syntax error -> 4')
    check(s.ask('!0L2147483648,0,0') == '5', '13.8 out of range -> 5')

    # 13.6.9 KEEP / RESTORE example sequence
    s.ask('!0N')
    s.ask('!0V2000')
    s.ask('!0A50')
    for _ in range(4):
        s.ask('!0C4000,0,0')
    s.wait(1_000_000_000)
    check(s.ask('!0H', 3_000_000_000) == '8', '13.6.9 !0H stops the vector')
    a = s.ask('!0P')
    check(a is not None and a.startswith('8,'), '13.6.9 !0P where we stopped (%r)' % a)
    stop_x = int(a.split(',')[1])
    check(s.ask('!0SR4') == '8,00', '13.6.9 !0SR4 (HALT, not an input)')
    check(s.ask('!0SR5') == '8,00', '13.6.9 !0SR5')
    check(s.ask('!0SR6') == '8,D0', '13.6.9 !0SR6: INTA=1 RUN=1 (rest in the queue)')
    check(s.ask('!0SW0,1A') == '8' and s.ask('!0SW1,3F') == '8', '13.6.9 new interrupt masks')
    check(s.ask('!0K') == '0', '13.6.9 !0K keeps and clears ST4-ST6')
    check(s.ask('!0C0,0,1') == '1', '13.6.9 after K only L vectors')
    check(s.ask('!0L0,0,-1000') == '0', '13.6.9 !0L0,0,-1000 lifts the tool')
    s.idle()
    check(s.ask('!0L0,0,1000') == '0', '13.6.9 !0L0,0,1000 lowers it')
    s.idle()
    check(s.ask('!0R') == '8', '13.6.9 !0R restores the queue and INTA')
    check(s.ask('!0SR6') == '8,D0', '13.6.9 restored ST6')
    check(s.ask('!0V500') == '8' and s.ask('!0XA') == '8', '13.6.9 !0V500 !0XA')
    check(s.ask('!0SW0,A2') == '8' and s.ask('!0SW1,78') == '8', '13.6.9 normal masks')
    check(s.ask('!0G') == '0', '13.6.9 !0G continues')
    s.idle(120)
    check(s.ask('!0PF') == '0,16000,0,0', '13.6.9 the kept queue completed (stopped at %d)' % stop_x)
    s.ask('!0SW0,00')
    s.ask('!0SW1,00')

    # 13.6.11 outputs
    check(s.ask('!0O0,FB') == '0' and s.state()['outputs'] == 'FB', '13.6.11 !0O0,FB switches OUT1 on')
    check(s.ask('!0O0,FF') == '0' and s.state()['outputs'] == 'FF', '13.6.11 !0O0,FF all off')

    # 13.7 spindle
    check(s.ask('!7V300') == '0', '13.7 !7V300')
    st = s.state()
    check(st['spindle'] == 300 and st['outputs'] == 'FE', '13.7 spindle 300 per mille, OUT0 on')
    check(s.ask('!7V0') == '0' and s.state()['outputs'] == 'FF', '13.7 !7V0 also switches OUT0 off')
    check(s.ask('!7V1001') == '5', '13.7 spindle above 1000 -> 5')
    check(s.ask('!7?') == '0,IP114/500 x16 16.9.2018', '13.7 address 7 answers ?')
    check(s.ask('!7L1,1,1') == '3', '13.7 address 7 does not know L')

    # 13.6.12 inputs and interrupts
    check(s.ask('!0I1') == '0,FF', '13.6.12 I1')
    check(s.ask('!0I2') == '0,FF', '13.6.12 I2')
    check(s.cmd('in 1 FE') == ['ok'], 'rig grounds IN0')
    check(s.ask('!0I1') == '0,FE', '13.6.12 I1 reads IN0 grounded')
    check(s.ask('!0SW0,01') == '8', '13.6.12 enabling Intr0 on an active input sets INTA')
    check(s.ask('!0SR4') == '8,01', '13.6.12 ST4 names the cause')
    s.cmd('in 1 FF')
    check(s.ask('!0SW0,00') == '8' and s.ask('!0D') == '0', 'interrupt cleared by D')
    # an input stops a running vector on a ramp
    s.ask('!0N')
    s.ask('!0V5000')
    s.ask('!0SW0,80')
    s.ask('!0L100000,0,0')
    s.wait(500_000_000)
    s.cmd('in 1 7F')
    a = s.ask('!0F')
    check(a is not None and int(a.split(',')[0], 16) & 8, '13.6.12 Intr7 sets INTA (%r)' % a)
    s.wait(1_000_000_000)
    a = s.ask('!0SR6')
    check(a == '8,C0', '13.6.12 stopped on the ramp, rest in the queue: INTA RUN (%r)' % a)
    s.cmd('in 1 FF')
    s.ask('!0SW0,00')
    check(s.ask('!0D') == '0', 'D')
    check(s.ask('!0V1000') == '0', 'V1000')

    # 13.6.7 reference run, manual example with a rig switch at Y=-1500
    s.ask('!0N')
    check(s.cmd('switch Y -1500') == ['ok'], 'rig places the Y switch')
    a = s.ask('!0WY-20000,1000,2000,500', 10_000_000_000)
    check(a == '0', '13.6.7 !0WY-20000,1000,2000,500 answers after the reference (%r)' % a)
    st = s.state()
    check(st['position'][1] == 0 and st['physical'][1] == -1499,
          '13.6.7 Y zeroed one step off the switch (%r %r)' % (st['position'], st['physical']))
    s.cmd('switch Y none')

    # 13.6.10 EEPROM
    check(s.ask('!0ER05') == '0,FF', '11.5 0x05 defaults to FF')
    check(s.ask('!0EW05,AC') == '0' and s.ask('!0ER05') == '0,AC', '11.5 example 0xAC written/read')
    check(s.ask('!0EW05,FF') == '0', 'restore 0x05')
    check(s.ask('!0EFW40,12.5') == '0' and s.ask('!0EFR40') == '0,12.5', '13.6.10 EFW/EFR float')
    check(s.ask('!0EUW48,500') == '0' and s.ask('!0EUR48') == '0,500', '13.6.10 EUW/EUR uint32')
    check(s.ask('!0EW100,00') == '5', '13.6.10 address above FF -> 5')

    # 13.6.8 MPG (as shipped: not enabled in EEPROM 0x06)
    check(s.ask('!0Y+') == '5', '12.2 Y+ refused while EEPROM 0x06 does not enable the MPG')
    check(s.ask('!0Y-') == '0,Y-', '13.6.8 Y- answers the command with its parameter')

    # 13.6.13 index and repeat
    a = s.ask('!0SR6')
    i1 = s.ask('!0@')
    check(s.ask('!0@') == i1, '13.6.13 @ does not count itself')
    s.ask('!0SR6')
    i2 = s.ask('!0@')
    check(int(i2.split(',')[1]) == (int(i1.split(',')[1]) + 1) % 256, '13.6.13 @ counts modulo 256')
    s.ask('!0PF')
    check(s.ask('!0>') == s.ask('!0PF'), '13.6.13 > repeats the last answer')

    # 13.8 error 2: the watchdog
    s.send_only('!0V10')
    a = s.wait(300_000_000)
    check(a == '2\r', '13.8 incomplete frame -> 2 (watchdog) (%r)' % a)

    # 13.5 reset state after J
    s.ask('!0V3000')
    s.ask('!0O0,00')
    s.ask('!0NX77')
    check(s.ask('!0J') == '0', '13.6.13 J answers')
    check(s.ask('!0SR6', 500_000_000) is None, '13.5 deaf during the ~2 s restart')
    s.wait(2_000_000_000)
    st = s.state()
    check(st['status'] == ['00'] * 7, '13.5 ST0..ST6 = 00')
    check(st['modal']['A'] == 20 and st['modal']['V'] == 1000 and st['modal']['$'] == 512,
          '13.5 A20 V1000 $512')
    check(st['modal']['B'] == 500000, '13.5 B = the model rate (B50000 on the 50 kHz unit)')
    check(s.ask('!0PF') == '0,0,0,0', '13.5 position counter zeroed')
    check(st['outputs'] == 'FF', '13.5 O0,FF outputs off')
    check(s.ask('!0@') == '0,1', '13.6.13 index restarts after J')
    s.close()

    # 10.1 COM SPEED switch read at power-on (EEPROM 0x0D = FF: 19200..115200)
    s = Sim('GVE114-50')
    check(s.ask('!0?') == '0,IP114/50 x16 16.9.2018', 'model GVE114-50 version')
    s.cmd('rate 0')
    s.cmd('power-on')
    s.wait(2_100_000_000)
    check(s.ask('!0?', 200_000_000) is None, '10.1 sw1/sw2 OFF/OFF: not heard at 115200')
    s.cmd('baud 19200')
    s.baud = 19200
    check(s.ask('!0SR0') == '0,00', '10.1 answers at 19200 Bd')
    check(s.state()['modal']['B'] == 50000, '13.5 B50000 on the 50 kHz version')
    s.close()

    print('\n%d passed, %d failed' % (passes, len(failures)))
    for f in failures:
        print('  FAILED:', f)
    return 0 if not failures else 1


if __name__ == '__main__':
    sys.exit(main())
