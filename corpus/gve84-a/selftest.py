#!/usr/bin/env python3
"""Self-test: the GVE84 manual's worked examples (and the cosim.md session
transcript) run against `sim.py --cosim` through the co-simulation protocol.

    python3 selftest.py        -> one line per example, exit status 0 if all pass
"""
import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))


class Sim:
    def __init__(self, *extra):
        self.p = subprocess.Popen([sys.executable, os.path.join(HERE, "sim.py"), "--cosim", *extra],
                                  stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, bufsize=1)
        self.hello = self.p.stdout.readline().strip()
        self.now = 0
        assert self.cmd("baud 115200") == ["ok"]

    def cmd(self, c):
        self.p.stdin.write(c + "\n")
        self.p.stdin.flush()
        out = []
        while True:
            line = self.p.stdout.readline().strip()
            out.append(line)
            if not line.startswith("rx "):
                if line.startswith("now "):
                    self.now = int(line.split()[1])
                return out

    @staticmethod
    def rx_of(lines):
        data = b""
        first = None
        for l in lines:
            if l.startswith("rx "):
                _, t, h = l.split()
                if first is None:
                    first = int(t)
                data += bytes.fromhex(h)
        return data.decode("latin-1"), first

    def frame(self, text, wait_ns=200_000_000):
        """Send one frame, wait for its answer (up to wait_ns after its end).
        Returns the answer without CR ('' when none)."""
        hexs = (text + "\r").encode("latin-1").hex().upper()
        end = self.now + len(text + "\r") * round(1e10 / 115200)
        lines = self.cmd("tx %s %d" % (hexs, end + wait_ns))
        ans, _ = self.rx_of(lines)
        return ans.rstrip("\r")

    def wait(self, ns):
        self.cmd("until %d" % (self.now + ns))

    def state(self):
        return json.loads(self.cmd("state")[-1])

    def close(self):
        try:
            self.p.stdin.write("quit\n")
            self.p.stdin.flush()
            self.p.wait(5)
        except Exception:
            self.p.kill()


def csum(s):
    return "%02X" % (sum(s.encode()) & 0xFF)


RESULTS = []


def example(name):
    def deco(fn):
        def run():
            sim = Sim()
            try:
                fn(sim)
                RESULTS.append((name, True, ""))
                print("PASS  %s" % name)
            except AssertionError as e:
                RESULTS.append((name, False, str(e)))
                print("FAIL  %s: %s" % (name, e))
            finally:
                sim.close()
        run.__name__ = fn.__name__
        EXAMPLES.append(run)
        return run
    return deco


EXAMPLES = []


def eq(got, want, what=""):
    assert got == want, "%s: got %r, want %r" % (what, got, want)


# ------------------------------------------------------------------ cosim.md
@example("cosim.md session: !0? -> '0,IP84 v3 27.1.2010', L100,0,0 timing, H answered 8 at 150.52 ms")
def ex_session(s):
    eq(s.hello.split()[:2], ["cosim", "1"], "handshake")
    st = s.state()
    eq(st["profile"], "GVE84-100", "profile")
    eq(st["position"], [0, 0, 0], "position")
    eq(s.cmd("tx 21303F0D 250781252")[-1], "now 2083344", "? answer end")
    out = s.cmd("tx 21304C3130302C302C300D 250954864")
    eq(Sim.rx_of(out), ("0\r", 3125016), "L answer")
    eq(out[-1], "now 3211822", "L now")
    eq(s.cmd("until 100000000"), ["now 100000000"], "until")
    eq(s.cmd("next"), ["next 155000000"], "next event = the vector's end")
    out = s.cmd("tx 2130480D 351302088")
    eq(Sim.rx_of(out), ("8\r", 150434030), "H answer")
    eq(out[-1], "now 150520836", "H now")
    eq(s.cmd("in 1 FE"), ["ok"], "rig in")


@example("12.2 / 12.5.1 ?: version string 'IP84 v3 27.1.2010'")
def ex_version(s):
    eq(s.frame("!0?"), "0,IP84 v3 27.1.2010", "!0?")


@example("12.5.1 Q: 8-digit processor id ddmmrrpp (example 25020304)")
def ex_q(s):
    a = s.frame("!0Q")
    assert a.startswith("0,") and len(a) == 10 and a[2:].isdigit(), a
    eq(a, "0,25020304", "!0Q")


# ------------------------------------------------------------------ 12.3.2
@example("12.3.2 !0%+ -> 0,5C (checksums on, answer already summed)")
def ex_cs_on(s):
    eq(s.frame("!0%+"), "0,5C", "!0%+")


@example("12.3.2 !0%-,CF -> 0 (checksums off, answer without sum)")
def ex_cs_off(s):
    eq(csum("!0%-,"), "CF", "sum of !0%-,")
    s.frame("!0%+")
    eq(s.frame("!0%-,CF"), "0", "!0%-,CF")
    eq(s.frame("!0F"), "0,00", "plain frame accepted after %-")


@example("12.3.2 !0A100, sums to 0x14F -> !0A100,4F, accepted with checksums on")
def ex_cs_a100(s):
    eq(sum(b"!0A100,"), 0x14F, "sum")
    eq(csum("!0A100,"), "4F", "checksum")
    s.frame("!0%+")
    eq(s.frame("!0A100,4F"), "0,5C", "!0A100,4F")
    eq(s.state()["modal"]["A"], 100, "A modal")


@example("12.3.2 with checksums on, a frame whose sum does not agree is not executed and errors")
def ex_cs_bad(s):
    s.frame("!0%+")
    a = s.frame("!0L1000,100,0,00")
    assert a[0] == "4" and a == "4," + csum("4,"), a
    eq(s.state()["queue"], 0, "vector not queued")


@example("12.3.2 !0L1000,100 (the manual's example command: X,Y given, Z=0)")
def ex_l2(s):
    eq(s.frame("!0L1000,100"), "0", "L1000,100")
    s.wait(3_000_000_000)
    eq(s.frame("!0PF"), "0,1000,100,0", "PF")


# ------------------------------------------------------------------ 12.3.3
PACKET = ["!0C697,30,0,51", "!0C692,92,0,54", "!0C682,151,0,7F", "!0C665,209,0,84",
          "!0C645,268,0,87", "!0C619,322,0,7F", "!0C589,375,0,8D", "!0C553,425,0,80",
          "!0C515,471,0,7F", "!0C471,515,0,7F"]


@example("12.3.3 packet: !0*S,FA, 10 C vectors, !0*E10,4D -> 0,10,E9")
def ex_packet(s):
    eq(csum("!0*S,"), "FA", "*S sum")
    eq(csum("!0*E10,"), "4D", "*E sum")
    for f in PACKET:
        body, cs = f.rsplit(",", 1)
        eq(csum(body + ","), cs, "sum of " + f)
    s.frame("!0%+")
    eq(s.frame("!0*S,FA", 5_000_000), "", "no answer to *S")
    for f in PACKET:
        eq(s.frame(f, 5_000_000), "", "no answer inside a packet")
    eq(s.frame("!0*E10,4D"), "0,10,E9", "packet end")
    st = s.state()
    assert st["queue"] >= 1 and not st["packet_open"], st


# ------------------------------------------------------------------ 12.6 table
@example("12.6 !0L1000,0,0 -> 0 (OK)")
def ex_t_l(s):
    eq(s.frame("!0L1000,0,0"), "0", "L")


@example("12.6 !0PF -> 0,-1000,2000,50")
def ex_t_pf(s):
    eq(s.frame("!0L-1000,2000,50"), "0", "L")
    s.wait(4_000_000_000)
    eq(s.frame("!0PF"), "0,-1000,2000,50", "PF")
    eq(s.frame("!0P"), "0,-1000,2000", "P (12.5.6: X,Y)")


@example("12.6 !0C100,20,0 -> 1 (queue of 64 vectors full, not accepted)")
def ex_t_full(s):
    for i in range(64):
        eq(s.frame("!0C100000,0,0", 1_000_000), "0", "C #%d" % i)
    eq(s.frame("!0F"), "0,60", "F: RUN and queue-full bit 5")
    eq(s.frame("!0C100,20,0"), "1", "65th C")


@example("12.6 !0V1000 -> 8 (OK, but interrupted: INTA=1)")
def ex_t_v(s):
    eq(s.frame("!0H"), "8", "H at rest")
    eq(s.frame("!0V1000"), "8", "V1000")


@example("12.6 !0SW8,F1 -> 5 (parameter out of range)")
def ex_t_sw8(s):
    eq(s.frame("!0SW8,F1"), "5", "SW8,F1")


@example("12.6 !0SR2 -> 0,2B")
def ex_t_sr2(s):
    eq(s.frame("!0SW2,2B"), "0", "SW2,2B")
    eq(s.frame("!0SR2"), "0,2B", "SR2")


# ------------------------------------------------------------------ 12.4
@example("12.4 reset (J): after ~2 s ST0..ST6=00, A20, V1000, $512, B=max, N, O0,FF")
def ex_reset(s):
    for f in ("!0SW0,07", "!0A50", "!0V2000", "!0$100", "!0B500", "!0O0,FB", "!0NX77"):
        eq(s.frame(f), "0", f)
    eq(s.frame("!0J"), "0", "J")
    eq(s.frame("!0F", 50_000_000), "", "deaf while restarting")
    s.wait(2_100_000_000)
    for n in range(7):
        eq(s.frame("!0SR%d" % n), "0,00", "SR%d" % n)
    eq(s.frame("!0PF"), "0,0,0,0", "counters zeroed")
    st = s.state()
    eq(st["outputs"], "FF", "outputs")
    m = st["modal"]
    eq((m["A"], m["V"], m["$"], m["B"]), (20, 1000, 512, 100000), "modal")


# ------------------------------------------------------------------ 12.5.x
@example("12.5.2 !0L1000,1000,20 and !0C1000,1000,20 accepted; L0,0,0 answers 1 until the queue is done")
def ex_vectors(s):
    eq(s.frame("!0L1000,1000,20"), "0", "L")
    eq(s.frame("!0C1000,1000,20"), "0", "C behind L")
    eq(s.frame("!0L0,0,0"), "1", "L0,0,0 while the queue runs")
    s.wait(5_000_000_000)
    eq(s.frame("!0L0,0,0"), "0", "L0,0,0 once done")
    s.wait(50_000_000)
    eq(s.frame("!0PF"), "0,2000,2000,40", "PF")


@example("12.5.2 !0T5 (1..24 ms), !0$n")
def ex_t(s):
    eq(s.frame("!0T5"), "0", "T5")
    eq(s.frame("!0T25"), "5", "T25 out of range")
    eq(s.frame("!0$512"), "0", "$512")


@example("12.5.3 !0A50, !0V10000, !0VL25000,25000,30000, !0B35000")
def ex_speeds(s):
    for f in ("!0A50", "!0V10000", "!0VL25000,25000,30000", "!0B35000"):
        eq(s.frame(f), "0", f)
    eq(s.frame("!0V9"), "5", "V below 10")
    eq(s.frame("!0V100001"), "5", "V above the GVE84-100's 100 kHz")
    m = s.state()["modal"]
    eq((m["A"], m["V"], m["VL"], m["B"]), (50, 10000, [25000, 25000, 30000], 35000), "modal")


@example("12.5.3 A50 = 50 000 pulses/s2 and V10000: L20000,0,0 takes 0.2+1.8+0.2 s")
def ex_ramp(s):
    eq(s.frame("!0A50"), "0", "A50")
    eq(s.frame("!0V10000"), "0", "V10000")
    eq(s.frame("!0L20000,0,0"), "0", "L")
    t_rx = s.now
    nxt = s.cmd("next")[0].split()
    start = int(nxt[1])                      # the motion starts (tick + T dwell)
    s.cmd("until %d" % (start + 100_000_000))
    eq(s.state()["position"][0], 250, "0.1 s into the ramp: a t^2/2 = 250 steps")
    s.cmd("until %d" % (start + 1_200_000_000))
    eq(s.state()["position"][0], 11000, "cruising: 1000 + 10000 steps")
    eq(s.cmd("next")[0], "next %d" % (start + 2_200_000_000), "vector ends after 2.2 s")
    assert start - t_rx < 3_000_000, "starts within the T dwell"


@example("12.5.5 XU: +1/16 of the current speed on the queued vector")
def ex_xu(s):
    eq(s.frame("!0L100000,0,0"), "0", "L")
    s.wait(1_000_000_000)
    p0 = s.state()["position"][0]
    s.wait(1_000_000_000)
    p1 = s.state()["position"][0]
    eq(p1 - p0, 1000, "V1000")
    eq(s.frame("!0XU"), "0", "XU")
    s.wait(1_000_000_000)
    p0 = s.state()["position"][0]
    s.wait(1_000_000_000)
    p1 = s.state()["position"][0]
    eq(p1 - p0, 1062, "1000 * 17/16 = 1062.5 steps/s")


@example("12.5.4/12.5.5 VK, VN, XA, XU, XD, !0XM100, !0XM200")
def ex_exchange(s):
    for f in ("!0VK", "!0VN", "!0XA", "!0XU", "!0XD", "!0XM100", "!0XM200"):
        eq(s.frame(f), "0", f)
    eq(s.state()["modal"]["XM"], 200, "XM")


@example("12.5.6 !0NX0, !0NX100; N refused while RUN=1")
def ex_null(s):
    eq(s.frame("!0NX100"), "0", "NX100")
    eq(s.frame("!0PF"), "0,100,0,0", "PF")
    eq(s.frame("!0NX0"), "0", "NX0")
    eq(s.frame("!0PF"), "0,0,0,0", "PF")
    eq(s.frame("!0L5000,0,0"), "0", "L")
    eq(s.frame("!0N"), "7", "N while running")
    st = s.state()
    eq(st["physical"][1:], [0, 0], "physical")


@example("12.5.7 !0WY,-20000,1000,2000,500 answers once the reference run is over; Y counter zeroed")
def ex_ref(s):
    eq(s.cmd("switch Y -1500"), ["ok"], "switch")
    t0 = s.now
    eq(s.frame("!0WY,-20000,1000,2000,500", 3_000_000_000), "0", "W")
    assert s.now - t0 > 1_500_000_000, "answer only after 1500 steps at 1000/s"
    eq(s.frame("!0PF"), "0,0,0,0", "PF")
    eq(s.state()["physical"], [0, -1499, 0], "released one step back from the switch")


@example("12.5.8 K/R example sequence (H, P, SR4-6, SW0/1, K, L up, L down, R, V500, XA, SW0/1, G)")
def ex_keep(s):
    for i in range(3):
        eq(s.frame("!0C5000,0,0"), "0", "C")
    s.wait(1_000_000_000)
    eq(s.frame("!0H", 1_000_000_000), "8", "H")
    p = s.frame("!0P")
    assert p.startswith("8,") and p.endswith(",0"), p
    eq(s.frame("!0SR4"), "8,00", "SR4")
    eq(s.frame("!0SR5"), "8,00", "SR5")
    eq(s.frame("!0SR6"), "8,D0", "SR6: INTA, RUN, INTCOM")
    eq(s.frame("!0SW0,1A"), "8", "SW0,1A")
    eq(s.frame("!0SW1,3F"), "8", "SW1,3F")
    eq(s.frame("!0K"), "0", "K clears ST4-6")
    eq(s.frame("!0C1,0,0"), "1", "C refused after K")
    eq(s.frame("!0L0,0,-1000"), "0", "L up")
    s.wait(3_000_000_000)
    eq(s.frame("!0L0,0,1000"), "0", "L down")
    s.wait(3_000_000_000)
    eq(s.frame("!0R"), "8", "R restores INTA=1")
    eq(s.frame("!0V500"), "8", "V500")
    eq(s.frame("!0XA"), "8", "XA")
    eq(s.frame("!0SW0,A2"), "8", "SW0,A2")
    eq(s.frame("!0SW1,78"), "8", "SW1,78")
    eq(s.frame("!0G"), "0", "G")
    eq(s.frame("!0SR6"), "0,40", "running again")
    eq(s.frame("!0PF").split(",")[3], "0", "Z back at 0")


@example("12.5.8 H/G/D and the INTA/RUN table of 12.5.11")
def ex_hgd(s):
    eq(s.frame("!0SR6"), "0,00", "INTA=0 RUN=0")
    eq(s.frame("!0L20000,0,0"), "0", "L")
    s.wait(100_000_000)
    eq(s.frame("!0SR6"), "0,40", "INTA=0 RUN=1")
    eq(s.frame("!0H", 1_000_000_000), "8", "H")
    eq(s.frame("!0SR6"), "8,D0", "INTA=1 RUN=1")
    eq(s.frame("!0G"), "0", "G")
    s.wait(30_000_000_000)
    eq(s.frame("!0G"), "6", "G with nothing stopped")
    eq(s.frame("!0L10,0,0"), "0", "L short")
    eq(s.frame("!0H", 1_000_000_000), "8", "H")
    eq(s.frame("!0D"), "8" if False else "0", "D clears ST4-6")
    eq(s.frame("!0SR6"), "0,00", "all clear")


@example("12.5.9 / 11 !0EW01,00 (relay = spindle), ER reads it back")
def ex_eeprom(s):
    eq(s.frame("!0EW01,00"), "0", "EW01,00")
    eq(s.frame("!0ER01"), "0,00", "ER01")
    eq(s.frame("!0ER05"), "0,FF", "ER05 default FF (11.3)")
    eq(s.frame("!0EW100,00"), "5", "address above FF")


@example("12.5.10 !0O0,FB (coolant OUT1 on), !0O0,FF (all off)")
def ex_out(s):
    eq(s.frame("!0O0,FB"), "0", "O0,FB")
    eq(s.state()["outputs"], "FB", "outputs")
    eq(s.frame("!0O0,FF"), "0", "O0,FF")
    eq(s.state()["outputs"], "FF", "outputs")


@example("12.5.11 I1 reads the port; an enabled input stops the motion and sets INTA/ST4")
def ex_in(s):
    eq(s.frame("!0I1"), "0,FF", "I1")
    eq(s.cmd("in 1 FE"), ["ok"], "ground IN0")
    eq(s.frame("!0I1"), "0,FE", "I1")
    eq(s.cmd("in 1 FF"), ["ok"], "release")
    eq(s.frame("!0SW0,01"), "0", "enable INTR0")
    eq(s.frame("!0L20000,0,0"), "0", "L")
    s.wait(500_000_000)
    eq(s.cmd("in 1 FE"), ["ok"], "ground IN0 while moving")
    s.wait(1_000_000_000)
    eq(s.frame("!0SR4"), "8,01", "ST4 cause INTR0")
    eq(s.frame("!0SR6"), "8,C0", "INTA=1 RUN=1, stopped")


@example("12.5.12 @ index (mod 256) and > repeat")
def ex_index(s):
    eq(s.frame("!0@"), "0,00", "@ after reset")
    s.frame("!0SR6")
    s.frame("!0SR6")
    eq(s.frame("!0@"), "0,02", "@")
    eq(s.frame("!0PF"), "0,0,0,0", "PF")
    eq(s.frame("!0>"), "0,0,0,0", "> repeats the last answer")


@example("12.6 errors: 3 unknown, 4 syntax, 2 watchdog")
def ex_errors(s):
    eq(s.frame("!0Y"), "3", "unknown")
    eq(s.frame("!0L1,2,3,4"), "4", "syntax")
    eq(s.frame("!0H5"), "4", "syntax")
    lines = s.cmd("tx 2130 %d" % (s.now + 500_000_000))
    ans, t = Sim.rx_of(lines)
    eq(ans, "2\r", "watchdog")


def main():
    for run in EXAMPLES:
        run()
    bad = [r for r in RESULTS if not r[1]]
    print("%d examples, %d passed, %d failed" % (len(RESULTS), len(RESULTS) - len(bad), len(bad)))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
