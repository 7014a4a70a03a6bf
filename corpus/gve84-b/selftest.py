#!/usr/bin/env python3
"""Self-test: the GVE84 manual's worked examples, run against sim.py through
the co-simulation protocol (given/cosim.md).  Exit status 0 when all pass."""
import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
B = round(10 * 10 ** 9 / 115200)
MS = 1_000_000


class Sim:
    def __init__(self, model="GVE84-100"):
        self.p = subprocess.Popen([sys.executable, os.path.join(HERE, "sim.py"),
                                   "--cosim", "--model", model],
                                  stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                  text=True, bufsize=1)
        first = self.p.stdout.readline().strip()
        assert first.startswith("cosim 1"), first
        self.now = 0
        assert self.cmd("baud 115200") == ["ok"]

    def cmd(self, line):
        self.p.stdin.write(line + "\n")
        self.p.stdin.flush()
        out = []
        while True:
            l = self.p.stdout.readline()
            if not l:
                raise RuntimeError("simulator ended")
            l = l.rstrip("\n")
            out.append(l)
            if not l.startswith("rx "):
                break
        last = out[-1]
        if last.startswith("now "):
            t = int(last.split()[1])
            assert t >= self.now, "time went backwards"
            self.now = t
        return out

    @staticmethod
    def rx_text(lines):
        s = b""
        for l in lines:
            if l.startswith("rx "):
                s += bytes.fromhex(l.split()[2])
        return s.decode("latin-1")

    def send(self, text, wait_ms=1000):
        """One frame (text without the CR); returns the answer without CR
        ('' when none came within wait_ms)."""
        data = (text + "\r").encode("latin-1")
        T = self.now + len(data) * B + int(wait_ms * MS)
        lines = self.cmd("tx %s %d" % (data.hex().upper(), T))
        ans = self.rx_text(lines)
        return ans[:-1] if ans.endswith("\r") else ans

    def until(self, t):
        return self.rx_text(self.cmd("until %d" % t))

    def wait_ms(self, ms):
        return self.until(self.now + int(ms * MS))

    def state(self):
        return json.loads(self.cmd("state")[0])

    def close(self):
        try:
            self.p.stdin.write("quit\n")
            self.p.stdin.flush()
            self.p.wait(5)
        except Exception:
            self.p.kill()


def cs(s):
    """Manual 12.3.2: append the checksum to a frame ending in a comma."""
    return s + "%02X" % (sum(s.encode("latin-1")) & 0xFF)


RESULTS = []


def check(name, got, want):
    ok = got == want
    RESULTS.append((name, ok, got, want))
    print("%s  %-58s got %r%s" % ("PASS" if ok else "FAIL", name, got,
                                  "" if ok else "  want %r" % (want,)))


# ------------------------------------------------------------------ tests
def t_session():
    """given/cosim.md 'A session', byte for byte and instant for instant."""
    s = Sim()
    st = s.state()
    check("session: state at start", (st["profile"], st["position"], st["physical"]),
          ("GVE84-100", [0, 0, 0], [0, 0, 0]))
    check("session: !0? reply", s.cmd("tx 21303F0D 250781252"),
          ["rx 434030 302C495038342076332032372E312E323031300D", "now 2083344"])
    check("session: !0L100,0,0 reply", s.cmd("tx 21304C3130302C302C300D 250954864"),
          ["rx 3125016 300D", "now 3211822"])
    check("session: until 100 ms", s.cmd("until 100000000"), ["now 100000000"])
    check("session: next", s.cmd("next"), ["next 155000000"])
    check("session: !0H answered at rest", s.cmd("tx 2130480D 351302088"),
          ["rx 150434030 380D", "now 150520836"])
    check("session: in 1 FE", s.cmd("in 1 FE"), ["ok"])
    s.close()


def t_checksums():
    s = Sim()
    check("12.3.2 !0%+ -> 0,5C", s.send("!0%+"), "0,5C")
    check("12.3.2 checksum of !0A100, is 4F", cs("!0A100,"), "!0A100,4F")
    check("12.3.2 !0A100,4F accepted", s.send("!0A100,4F"), "0,5C")
    check("12.3.2 bad checksum refused", s.send("!0A100,4E"), "4,60")
    good = cs("!0L1000,100,0,")
    bad = good.replace("L1000", "L100")          # "vypadla nějaká nula"
    check("12.3.2 a zero dropped from !0L1000,100: refused", s.send(bad), "4,60")
    check("12.3.2 nothing moved", s.send(cs("!0PF,")), cs("0,0,0,0,"))
    check("12.3.2 the intact frame is taken", s.send(good), "0,5C")
    check("12.3.2 !0%-,CF -> 0", s.send("!0%-,CF"), "0")
    check("12.3.2 after %- no checksum", s.send("!0A20"), "0")
    s.close()


PACKET = ["!0C697,30,0,51", "!0C692,92,0,54", "!0C682,151,0,7F", "!0C665,209,0,84",
          "!0C645,268,0,87", "!0C619,322,0,7F", "!0C589,375,0,8D", "!0C553,425,0,80",
          "!0C515,471,0,7F", "!0C471,515,0,7F"]


def t_packet():
    s = Sim()
    check("12.3.3 checksums in the manual's packet", [cs(p.rsplit(",", 1)[0] + ",") for p in PACKET],
          PACKET)
    check("12.3.3 %+", s.send("!0%+"), "0,5C")
    check("12.3.3 !0*S,FA no answer", s.send("!0*S,FA", wait_ms=20), "")
    for p in PACKET:
        check("12.3.3 %s no answer" % p, s.send(p, wait_ms=5), "")
    check("12.3.3 !0*E10,4D -> 0,10,E9", s.send("!0*E10,4D"), "0,10,E9")
    s.wait_ms(20000)
    x = sum(int(p[3:].split(",")[0]) for p in PACKET)
    y = sum(int(p.split(",")[1]) for p in PACKET)
    check("12.3.3 packet vectors executed (PF)", s.send(cs("!0PF,")),
          cs("0,%d,%d,0," % (x, y)))
    # the whole string in one write, as the manual recommends
    data = "\r".join(["!0*S,FA"] + PACKET + ["!0*E10,4D"]) + "\r"
    lines = s.cmd("tx %s %d" % (data.encode().hex(), s.now + len(data) * B + 500 * MS))
    check("12.3.3 packet in one write -> 0,10,E9", Sim.rx_text(lines), "0,10,E9\r")
    check("12.3.3 %-,CF", s.send("!0%-,CF"), "0")
    s.close()


def t_reset():
    s = Sim()
    s.send("!0SW0,07")
    s.send("!0O0,00")
    s.send("!0NX55")
    check("12.4 power-on", s.cmd("power-on"), ["ok"])
    check("12.4 deaf during restart", s.send("!0?", wait_ms=100), "")
    s.until(2 * 10 ** 9 + s.now)
    for n in range(7):
        check("12.4 ST%d = 00" % n, s.send("!0SR%d" % n), "0,00")
    check("12.4 N: counters zeroed", s.send("!0PF"), "0,0,0,0")
    check("12.4 O0,FF", s.state()["outputs"], "FF")
    st = s.state()["modal"]
    check("12.4 A20 V1000 $512", (st["A"], st["V"], st["$"]), (20, 1000, 512))
    check("12.4 checksums off", s.send("!0F"), "0,00")
    s.close()


def t_ident_vectors():
    s = Sim()
    check("12.5.1 ? version", s.send("!0?"), "0,IP84 v3 27.1.2010")
    q = s.send("!0Q")
    check("12.5.1 Q: 8 digits ddmmrrpp", (q[:2], len(q[2:]), q[2:].isdigit()),
          ("0,", 8, True))
    check("12.5.2 !0L1000,1000,20", s.send("!0L1000,1000,20"), "0")
    check("12.5.2 L0,0,0 refused (1) while the queue is not done", s.send("!0L0,0,0"), "1")
    check("12.5.11 F while running: RUN", s.send("!0F"), "0,40")
    s.wait_ms(3000)
    check("12.5.2 L0,0,0 accepted once done", s.send("!0L0,0,0"), "0")
    s.wait_ms(50)
    check("12.5.6 PF after L1000,1000,20", s.send("!0PF"), "0,1000,1000,20")
    check("12.5.6 P", s.send("!0P"), "0,1000,1000")
    check("12.5.2 !0C1000,1000,20", s.send("!0C1000,1000,20"), "0")
    s.wait_ms(3000)
    check("12.5.2 C executed", s.send("!0PF"), "0,2000,2000,40")
    s.close()


def t_answer_table():
    """12.6 'Např.' table."""
    s = Sim()
    check("12.6 !0L1000,0,0 -> 0", s.send("!0L1000,0,0"), "0")
    s.wait_ms(2500)
    s.send("!0NX-1000")
    s.send("!0NY2000")
    s.send("!0NZ50")
    check("12.6 !0PF -> 0,-1000,2000,50", s.send("!0PF"), "0,-1000,2000,50")
    # fill the queue: slow C vectors, 64 of them (1 running + 63 queued)
    s.send("!0V10")
    codes = [s.send("!0C1000,0,0") for _ in range(64)]
    check("12.6 64 C vectors taken", set(codes), {"0"})
    check("12.5.11 F: queue full bit 5", s.send("!0F"), "0,60")
    check("12.6 !0C100,20,0 -> 1 (queue full)", s.send("!0C100,20,0"), "1")
    check("12.5.8 H while running -> 8 at rest", s.send("!0H", wait_ms=1000), "8")
    check("12.6 !0V1000 -> 8 (OK, INTA=1)", s.send("!0V1000"), "8")
    check("12.5.11 SR6 after H: INTA RUN INTCOM", s.send("!0SR6"), "8,D0")
    check("12.5.8 D", s.send("!0D"), "0")
    check("12.6 !0SW8,F1 -> 5", s.send("!0SW8,F1"), "5")
    check("12.6 SW2,2B", s.send("!0SW2,2B"), "0")
    check("12.6 !0SR2 -> 0,2B", s.send("!0SR2"), "0,2B")
    check("12.6 unknown command -> 3", s.send("!0Y"), "3")
    check("12.6 syntax -> 4", s.send("!0L1,2"), "4")
    check("12.6 out of range -> 5", s.send("!0T25"), "5")
    check("12.6 G with nothing to start -> 6", s.send("!0G"), "6")
    s.send("!0V1000")
    s.send("!0L5000,0,0")
    check("12.6 N while running -> 7", s.send("!0N"), "7")
    s.close()


def t_modal_examples():
    s = Sim()
    for f in ["!0T5", "!0A50", "!0V10000", "!0VL25000,25000,30000", "!0B5000",
              "!0$512", "!0VK", "!0VN", "!0XM100", "!0XM200", "!0XA", "!0XU", "!0XD"]:
        check("12.5 %s -> 0" % f, s.send(f), "0")
    check("12.5.6 !0NX0", s.send("!0NX0"), "0")
    check("12.5.6 !0NX100", s.send("!0NX100"), "0")
    check("12.5.6 NX100 read back", s.send("!0PF"), "0,100,0,0")
    check("12.5.6 N", s.send("!0N"), "0")
    check("12.5.6 N read back", s.send("!0PF"), "0,0,0,0")
    s.close()


def t_reference():
    s = Sim()
    check("rig switch Y -1500", s.cmd("switch Y -1500"), ["ok"])
    check("12.5.7 !0WY,-20000,1000,2000,500 -> 0 after the run",
          s.send("!0WY,-20000,1000,2000,500", wait_ms=1000), "")
    ans = s.wait_ms(5000)
    check("12.5.7 W answered", ans, "0\r")
    st = s.state()
    check("12.5.7 Y counter zeroed at the switch", st["position"][1], 0)
    check("12.5.7 Y released one step back", st["physical"][1], -1499)
    check("12.5.7 overshoot beyond the switch", st["excursion"][1][0] < -1500, True)
    s.close()


def t_keep_restore():
    """12.5.8: the KEEP/RESTORE example sequence."""
    s = Sim()
    s.send("!0V2000")
    for _ in range(4):
        s.send("!0C3000,0,0")
    s.wait_ms(1000)
    check("K/R !0H", s.send("!0H"), "8")
    p = s.send("!0P")
    check("K/R !0P", p.startswith("8,"), True)
    check("K/R !0SR4", s.send("!0SR4"), "8,00")
    check("K/R !0SR5", s.send("!0SR5"), "8,00")
    check("K/R !0SR6 (INTA, RUN, INTCOM)", s.send("!0SR6"), "8,D0")
    check("K/R !0SW0,1A", s.send("!0SW0,1A"), "8")
    check("K/R !0SW1,3F", s.send("!0SW1,3F"), "8")
    check("K/R !0K", s.send("!0K"), "0")
    check("K/R !0L0,0,-1000", s.send("!0L0,0,-1000"), "0")
    check("K/R C refused under KEEP", s.send("!0C1,0,0"), "1")
    s.wait_ms(3000)
    check("K/R !0L0,0,1000", s.send("!0L0,0,1000"), "0")
    s.wait_ms(3000)
    check("K/R !0R", s.send("!0R"), "8")
    check("K/R !0V500", s.send("!0V500"), "8")
    check("K/R !0XA", s.send("!0XA"), "8")
    check("K/R !0SW0,A2", s.send("!0SW0,A2"), "8")
    check("K/R !0SW1,78", s.send("!0SW1,78"), "8")
    check("K/R !0G", s.send("!0G"), "0")
    s.wait_ms(60000)
    check("K/R queue finished", s.send("!0PF"), "0,12000,0,0")
    s.close()


def t_eeprom_io():
    s = Sim()
    check("11 !0EW01,00", s.send("!0EW01,00"), "0")
    check("11 !0ER01", s.send("!0ER01"), "0,00")
    check("11.3 ER05 default FF", s.send("!0ER05"), "0,FF")
    check("12.5.10 !0O0,FB", s.send("!0O0,FB"), "0")
    check("12.5.10 output port FB", s.state()["outputs"], "FB")
    check("12.5.10 !0O0,FF", s.send("!0O0,FF"), "0")
    check("12.5.11 I1", s.send("!0I1"), "0,FF")
    s.cmd("in 1 FE")
    check("12.5.11 I1 after grounding IN0", s.send("!0I1"), "0,FE")
    check("12.5.11 SW0,01 enables INTR0: INTA", s.send("!0SW0,01"), "8")
    check("12.5.11 ST4 cause", s.send("!0SR4"), "8,01")
    s.cmd("in 1 FF")
    check("12.5.8 D clears", s.send("!0D"), "0")
    s.close()


def t_recovery():
    s = Sim()
    s.send("!0SR6")
    s.send("!0SR6")
    check("12.5.12 @ index", s.send("!0@"), "0,2")
    check("12.5.12 > repeats the last answer", s.send("!0>"), "0,2")
    s.send("!0PF")
    check("12.5.12 > after PF", s.send("!0>"), "0,0,0,0")
    # watchdog: an unfinished frame
    lines = s.cmd("tx %s %d" % (b"!0L1".hex(), s.now + 4 * B + 1000 * MS))
    check("12.6 code 2: watchdog on an unfinished frame", Sim.rx_text(lines), "2\r")
    check("12.5.12 J -> 0 then reset", s.send("!0J", wait_ms=10), "0")
    s.until(s.now + 2100 * MS)
    check("12.5.12 index after J", s.send("!0@"), "0,0")
    s.close()


def main():
    for t in [t_session, t_checksums, t_packet, t_reset, t_ident_vectors,
              t_answer_table, t_modal_examples, t_reference, t_keep_restore,
              t_eeprom_io, t_recovery]:
        try:
            t()
        except Exception as e:  # a crash is a failure
            RESULTS.append((t.__name__, False, repr(e), None))
            print("FAIL  %s crashed: %r" % (t.__name__, e))
    bad = [r for r in RESULTS if not r[1]]
    print("\n%d checks, %d failed" % (len(RESULTS), len(bad)))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
