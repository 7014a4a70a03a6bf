#!/usr/bin/env python3
"""Runs the worked examples of the GVE54 instruction-set document against sim.py
through the co-simulation protocol.  One line per example; exit 0 when all pass."""
import sys
import traceback

from cosimclient import Sim

RESULTS = []


def example(name):
    def deco(fn):
        RESULTS.append((name, fn))
        return fn
    return deco


def eq(got, want, what=''):
    if got != want:
        raise AssertionError('%s: got %r, want %r' % (what, got, want))


def run_to_idle(s, limit=200):
    """Step from event to event (cosim 'next') until F reads RUN=0 or INTA."""
    for _ in range(limit):
        f = int(s.frame('!0F').split(',')[1], 16)
        if not f & 0x40 or f & 0x80:
            return f
        t = s.next()
        if t is None:
            raise AssertionError('RUN=1 and nothing due')
        s.until(t)
    raise AssertionError('still running')


# ---------------------------------------------------------------- RESET section
@example('RESET: ST0..ST6=00, MD, MF, A20, V1000, $512, B50000, N, O0,FF')
def ex_reset(s):
    for n in range(7):
        eq(s.frame('!0SR%d' % n), '0,00', 'SR%d' % n)
    st = s.state()
    eq(st['outputs'], 'FF', 'outputs')
    eq(st['current'], 'half', 'MD')
    eq(st['microstep'], 16, 'MF')
    eq((st['modal']['A'], st['modal']['V'], st['modal']['$'], st['modal']['B']),
       (20, 1000, 512, 50000), 'modal')
    eq(s.frame('!0PF'), '0,0,0,0', 'PF')
    # V1000/A20 measured: a long vector cruises at 1000 pulses/s
    eq(s.frame('!0L3000,0,0'), '0')
    s.wait_ms(1000)
    x1 = int(s.frame('!0PF').split(',')[1])
    s.wait_ms(1000)
    x2 = int(s.frame('!0PF').split(',')[1])
    assert abs((x2 - x1) - 1000) <= 2, (x1, x2)
    # J resets again, the counter included, deaf ~2 s
    run_to_idle(s)
    eq(s.frame('!0V5000'), '0')
    eq(s.frame('!0J'), '0', 'J')
    eq(s.frame('!0SR6', 100_000_000), None, 'deaf after J')
    s.wait_ms(2000)
    eq(s.frame('!0PF'), '0,0,0,0', 'PF after J')
    eq(s.state()['modal']['V'], 1000, 'V after J')


# ---------------------------------------------------------------- L / C examples
@example('!0L1000,1000,20 -> 0 (LINE example)')
def ex_line(s):
    eq(s.frame('!0L1000,1000,20'), '0')
    run_to_idle(s)
    eq(s.frame('!0PF'), '0,1000,1000,20')


@example('!0C1000,1000,20 -> 0 (CONT.LINE example)')
def ex_cont(s):
    eq(s.frame('!0C1000,1000,20'), '0')
    eq(s.frame('!0C1000,1000,20'), '0')
    run_to_idle(s)
    eq(s.frame('!0PF'), '0,2000,2000,40')


@example('L0,0,0 at the end of the queue: 1 until the queue is done, then 0')
def ex_l000(s):
    for _ in range(3):
        eq(s.frame('!0C2000,0,0'), '0')
    eq(s.frame('!0L0,0,0'), '1', 'queue not done')
    tries = 0
    while True:
        a = s.frame('!0L0,0,0')
        if a == '0':
            break
        eq(a, '1')
        tries += 1
        s.wait_ms(50)
    assert tries > 5
    eq(s.frame('!0PF'), '0,6000,0,0', 'queue before it done')


@example('!0T5 -> 0 (pause 5 ms between non-continuing vectors)')
def ex_T(s):
    eq(s.frame('!0T5'), '0')
    eq(s.frame('!0L1,0,0'), '0')
    run_to_idle(s)
    eq(s.frame('!0L1,0,0'), '0')
    t0 = s.now
    eq(s.frame('!0PF', 2_000_000), '0,1,0,0', 'the second L waits')
    s.until(t0 + 3_000_000)
    eq(s.frame('!0PF', 2_000_000), '0,1,0,0', 'still within 5 ms')
    run_to_idle(s)
    eq(s.frame('!0PF'), '0,2,0,0')
    eq(s.frame('!0T0'), '5', 'T0 out of range')
    eq(s.frame('!0T25'), '5', 'T25 out of range')


@example('!0V10000 -> 0 (velocity 10000 pulses/s)')
def ex_V(s):
    eq(s.frame('!0V10000'), '0')
    eq(s.frame('!0A255'), '0')
    eq(s.frame('!0L60000,0,0'), '0')
    s.wait_ms(1000)
    x1 = s.state()['position'][0]
    s.wait_ms(1000)
    x2 = s.state()['position'][0]
    assert abs((x2 - x1) - 10000) <= 10, (x1, x2)
    eq(s.frame('!0V39'), '5')
    eq(s.frame('!0V50001'), '5')


@example('!0A50 -> 0 (acceleration 50000 pulses/s2)')
def ex_A(s):
    eq(s.frame('!0A50'), '0')
    eq(s.frame('!0V50000'), '0')
    eq(s.frame('!0L60000,0,0'), '0')
    t0 = s.now
    s.until(t0 + 100_000_000)
    x = int(s.frame('!0PF', 2_000_000).split(',')[1])
    # 1/2 a t^2 = 250 pulses after 100 ms (the PF answer itself takes a little)
    assert 240 <= x <= 270, x


# ---------------------------------------------------------------- KEEP / RESTORE example
@example('KEEP/RESTORE example: H, P, SR4-6, SW0/1, K, L up, L down, R, V500, XA, SW0/1, G')
def ex_keep(s):
    eq(s.frame('!0V2000'), '0')
    eq(s.frame('!0L20000,0,0'), '0')
    eq(s.frame('!0C0,20000,0'), '0')
    s.wait_ms(500)
    eq(s.frame('!0H', 5_000_000_000), '8', 'H: INTA=1')
    p = s.frame('!0P')
    assert p.startswith('8,'), p
    hx, hy = (int(v) for v in p.split(',')[1:])
    assert 0 < hx < 20000 and hy == 0
    eq(s.frame('!0SR4'), '8,00')
    eq(s.frame('!0SR5'), '8,00')
    eq(s.frame('!0SR6'), '8,D0', 'INTA, RUN, INTCOM')
    eq(s.frame('!0SW0,1A'), '8')
    eq(s.frame('!0SW1,3F'), '8')
    eq(s.frame('!0K'), '0', 'K clears ST6')
    eq(s.frame('!0SR6'), '0,00')
    eq(s.frame('!0L0,0,-1000'), '0', 'tool up')
    run_to_idle(s)
    eq(s.frame('!0PF'), '0,%d,%d,-1000' % (hx, hy))
    eq(s.frame('!0L0,0,1000'), '0', 'tool down')
    run_to_idle(s)
    eq(s.frame('!0R'), '8', 'R restores INTA')
    eq(s.frame('!0SR6'), '8,D0')
    eq(s.frame('!0V500'), '8')
    eq(s.frame('!0XA'), '8')
    eq(s.frame('!0SW0,A2'), '8')
    eq(s.frame('!0SW1,78'), '8')
    eq(s.frame('!0G'), '0', 'G')
    f = run_to_idle(s)
    eq(f, 0)
    eq(s.frame('!0PF'), '0,20000,20000,0', 'the rest of the queue done')


# ---------------------------------------------------------------- HALT / GO / DELETE
@example('H answers only after the stop; RUN tells whether H came while running')
def ex_halt(s):
    eq(s.frame('!0H'), '8', 'H at rest answers at once')
    eq(s.frame('!0SR6'), '8,90', 'INTA, INTCOM, RUN=0')
    eq(s.frame('!0G'), '6', 'G: nothing to start')
    eq(s.frame('!0SR6'), '0,00', 'G cleared INTA, INTCOM')
    eq(s.frame('!0G'), '6', 'G without INTA: no effect')
    eq(s.frame('!0V5000'), '0')
    eq(s.frame('!0L60000,0,0'), '0')
    s.wait_ms(300)
    t0 = s.now
    eq(s.frame('!0H'), '8')
    assert s.now - t0 > 50_000_000, 'answered only after the ramp'
    eq(s.frame('!0SR6'), '8,D0')
    eq(s.frame('!0N'), 'F', 'N with RUN=1: 7 with INTA')
    eq(s.frame('!0D'), '0', 'D deletes the rest')
    eq(s.frame('!0SR6'), '0,00')
    eq(s.frame('!0N'), '0')
    eq(s.frame('!0PF'), '0,0,0,0')


@example('INTA/RUN table and error 7 while a vector runs')
def ex_table(s):
    eq(s.frame('!0L16000,0,0'), '0')
    eq(s.frame('!0SR6'), '0,40', 'INTA=0 RUN=1')
    eq(s.frame('!0D'), '7')
    eq(s.frame('!0N'), '7')
    eq(s.frame('!0MF'), '7')
    eq(s.frame('!0K'), '7')
    run_to_idle(s)
    eq(s.frame('!0SR6'), '0,00', 'INTA=0 RUN=0')
    eq(s.frame('!0L100,0,0'), '0')
    s.wait_ms(5)
    eq(s.frame('!0H'), '8')
    eq(s.frame('!0SR6'), '8,D0', 'INTA=1 RUN=1')


# ---------------------------------------------------------------- microsteps
@example('M4, L100,100,100, PF -> 0,400,400,400')
def ex_m4(s):
    eq(s.frame('!0M4'), '0')
    eq(s.frame('!0L100,100,100'), '0')
    run_to_idle(s)
    eq(s.frame('!0PF'), '0,400,400,400')
    eq(s.frame('!0P'), '0,400,400', 'P also in 1/16')


@example('PF=0,1001,500,399 (1/16), L-1,0,1 -> PF=0,1000,500,400, M4')
def ex_round(s):
    eq(s.frame('!0L1001,500,399'), '0')
    run_to_idle(s)
    eq(s.frame('!0PF'), '0,1001,500,399')
    eq(s.frame('!0L-1,0,1'), '0')
    run_to_idle(s)
    eq(s.frame('!0PF'), '0,1000,500,400')
    eq(s.frame('!0M4'), '0')
    eq(s.frame('!0L1,1,1'), '0')
    run_to_idle(s)
    eq(s.frame('!0PF'), '0,1004,504,404')
    eq(s.frame('!0M2'), '0')
    eq(s.frame('!0M8'), '0')
    eq(s.frame('!0MU'), '0')
    eq(s.frame('!0MD'), '0')
    eq(s.frame('!0MX'), '5')


# ---------------------------------------------------------------- answers table
@example('!0L1000,0,0 -> 0')
def ex_a1(s):
    eq(s.frame('!0L1000,0,0'), '0')


@example('!1PF -> 0,-1000,2000,50 (unit at address 1)')
def ex_a2(_):
    s = Sim('--address', '1')
    try:
        eq(s.frame('!1L-1000,2000,50'), '0')
        eq(s.frame('!0PF', 50_000_000), None, 'another address: no answer')
        for _ in range(500):
            if s.frame('!1F') == '0,00':
                break
            s.wait_ms(10)
        eq(s.frame('!1PF'), '0,-1000,2000,50')
    finally:
        s.close()


@example('!0C100,20,0 -> 1 (queue full: 96 vectors)')
def ex_a3(s):
    eq(s.frame('!0V40'), '0')
    for i in range(96):
        eq(s.frame('!0C100,20,0'), '0', 'vector %d' % i)
    eq(s.frame('!0F'), '0,60', 'F bit 5: full')
    eq(s.frame('!0C100,20,0'), '1')


@example('!0V1000 -> 8 (OK, interrupted: INTA=1)')
def ex_a4(s):
    eq(s.frame('!0H'), '8')
    eq(s.frame('!0V1000'), '8')


@example('!0SW8,F1 -> 5 (parameter out of range)')
def ex_a5(s):
    eq(s.frame('!0SW8,F1'), '5')


@example('!1SR2 -> 0,2B (unit at address 1)')
def ex_a6(_):
    s = Sim('--address', '1')
    try:
        eq(s.frame('!1SW2,2B'), '0')
        eq(s.frame('!1SR2'), '0,2B')
    finally:
        s.close()


@example('error codes 2, 3, 4, 5 (answer section)')
def ex_errors(s):
    eq(s.raw(b'!0PF'), '')
    eq(s.wait_ms(200), '2\r', 'watchdog: frame not complete in time')
    eq(s.frame('!0Z'), '3')
    eq(s.frame('!0L1,2'), '4')
    eq(s.frame('!0L70000,0,0'), '5')
    eq(s.frame('!0ER100'), '5')
    eq(s.frame('!0I3'), '5')
    eq(s.frame('!0O1,00'), '5')


# ---------------------------------------------------------------- other commands
@example('Q -> 8 digits ddmmrrpp; ? -> version')
def ex_q(s):
    a = s.frame('!0Q')
    assert a.startswith('0,') and len(a) == 10 and a[2:].isdigit(), a
    v = s.frame('!0?')
    assert v.startswith('0,') and 'Ip54v3' in v, v


@example('@ index modulo 256 and > repeat')
def ex_index(s):
    eq(s.frame('!0@'), '0,00')
    eq(s.frame('!0V1000'), '0')
    eq(s.frame('!0A20'), '0')
    eq(s.frame('!0@'), '0,02')
    eq(s.frame('!0PF'), '0,0,0,0')
    eq(s.frame('!0>'), '0,0,0,0')
    eq(s.frame('!0@'), '0,03')


@example('O0,n outputs active low; I0..I2 read the ports; ER/EW EEPROM')
def ex_io(s):
    eq(s.frame('!0O0,FE'), '0')
    eq(s.state()['outputs'], 'FE')
    s.rig('in 0 A5')
    eq(s.frame('!0I0'), '0,A5')
    s.rig('in 2 3C')
    eq(s.frame('!0I2'), '0,3C')
    eq(s.frame('!0EW1F,5A'), '0')
    eq(s.frame('!0ER1F'), '0,5A')


@example('Intr: an enabled input stops motion by a ramp, ST4 cause, INTA')
def ex_intr(s):
    eq(s.frame('!0SW0,80'), '0', 'enable Intr7 (Stop)')
    eq(s.frame('!0V5000'), '0')
    eq(s.frame('!0L60000,0,0'), '0')
    s.wait_ms(300)
    s.rig('in 1 7F')
    eq(s.frame('!0SR4'), '8,80')
    s.until(s.next())
    eq(s.frame('!0SR6'), '8,C0', 'stopped, rest of the vector held')
    x = s.state()['position'][0]
    s.wait_ms(100)
    eq(s.state()['position'][0], x, 'held')
    s.rig('in 1 FF')
    eq(s.frame('!0G'), '0')
    eq(s.frame('!0SR6'), '0,40')


@example('XU / XD change the queued speed by 1/16')
def ex_x(s):
    eq(s.frame('!0V1600'), '0')
    eq(s.frame('!0L60000,0,0'), '0')
    s.wait_ms(500)
    eq(s.frame('!0XU'), '0')
    s.wait_ms(500)
    x1 = s.state()['position'][0]
    s.wait_ms(1000)
    x2 = s.state()['position'][0]
    assert abs((x2 - x1) - 1700) <= 2, x2 - x1
    eq(s.frame('!0XD'), '0')
    eq(s.frame('!0XD'), '0')
    s.wait_ms(500)
    x1 = s.state()['position'][0]
    s.wait_ms(1000)
    x2 = s.state()['position'][0]
    # 1700 - 106 = 1594, 1594 - 99 = 1495
    assert abs((x2 - x1) - 1495) <= 2, x2 - x1


def main():
    failed = 0
    for name, fn in RESULTS:
        s = None
        try:
            s = Sim()
            fn(s)
            print('PASS  %s' % name)
        except Exception as e:
            failed += 1
            print('FAIL  %s: %s' % (name, e))
            if '-v' in sys.argv:
                traceback.print_exc()
        finally:
            if s is not None:
                s.close()
    print('%d of %d examples passed' % (len(RESULTS) - failed, len(RESULTS)))
    return 1 if failed else 0


if __name__ == '__main__':
    sys.exit(main())
