#!/usr/bin/env python3
"""Runs the manual's worked examples (and the reset state) through sim.py over
the co-simulation protocol (given/cosim.md).  PASS/FAIL per check; exit 0 when
all pass.  Standard library only."""
import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
B = round(10 * 10**9 / 115200)
FAILS = []


def check(name, got, want):
    ok = got == want
    print("%s  %s%s" % ("PASS" if ok else "FAIL", name,
                        "" if ok else "   got %r, want %r" % (got, want)))
    if not ok:
        FAILS.append(name)


def cs(text):
    """Append the manual's checksum (12.3.2): ',' + sum of all chars mod 256."""
    text += ","
    return text + "%02X" % (sum(text.encode()) & 0xFF)


class Sim:
    def __init__(self, *args):
        self.p = subprocess.Popen([sys.executable, os.path.join(HERE, "sim.py"), "--cosim"]
                                  + list(args), stdin=subprocess.PIPE,
                                  stdout=subprocess.PIPE, text=True, bufsize=1)
        self.first = self.p.stdout.readline().rstrip("\n")
        self.now = 0

    def cmd(self, line):
        self.p.stdin.write(line + "\n")
        self.p.stdin.flush()
        lines = []
        while True:
            r = self.p.stdout.readline().rstrip("\n")
            lines.append(r)
            if not r.startswith("rx "):
                break
        last = lines[-1]
        if last.startswith("now "):
            self.now = int(last.split()[1])
        return lines

    def batch(self, line):
        """A batch reply: each frame's rx lines and now; it ends after the last frame
        or after the first frame during which no CR reached the host (batch-stops)."""
        frames = (len(line.split()) - 1) // 2
        self.p.stdin.write(line + "\n")
        self.p.stdin.flush()
        lines, cr = [], False
        while True:
            r = self.p.stdout.readline().rstrip("\n")
            lines.append(r)
            if r.startswith("rx "):
                cr = cr or r.endswith("0D")
                continue
            if not r.startswith("now "):
                return lines
            self.now = int(r.split()[1])
            frames -= 1
            if frames == 0 or not cr:
                return lines
            cr = False

    @staticmethod
    def answer(lines):
        data = b""
        for ln in lines:
            if ln.startswith("rx "):
                data += bytes.fromhex(ln.split()[2])
        return data.decode("latin-1")

    def frame(self, text, wait=50_000_000):
        """Send '!'+text+CR, wait up to `wait` ns for the answer; return it (no CR)."""
        data = ("!" + text + "\r").encode()
        end = self.now + len(data) * B
        return self.answer(self.cmd("tx %s %d" % (data.hex().upper(), end + wait))).rstrip("\r")

    def until(self, t):
        return self.answer(self.cmd("until %d" % t)).rstrip("\r")

    def state(self):
        return json.loads(self.cmd("state")[0])

    def quit(self):
        self.p.stdin.write("quit\n")
        self.p.stdin.flush()
        self.p.wait(timeout=10)


def test_session():
    """given/cosim.md 'A session' (the manual's '?', L, H) at its exact instants."""
    s = Sim()
    check("handshake: first line", s.first.split()[:2], ["cosim", "1"])
    check("baud", s.cmd("baud 115200"), ["ok"])
    st = s.state()
    check("reset state: status ST0..ST6 = 00", st["status"], ["00"] * 7)
    check("reset state: counters 0", st["position"], [0, 0, 0])
    check("reset state: output O0,FF", st["outputs"], "FF")
    check("reset state: checksums off, index 0", (st["checksums"], st["index"]), (False, 0))
    check("reset state: A20 V1000 $512", (st["modal"]["A"], st["modal"]["V"], st["modal"]["$"]),
          (20, 1000, 512))
    check("session: !0? exchange", s.cmd("tx 21303F0D 250781252"),
          ["rx 434030 302C495038342076332032372E312E323031300D", "now 2083344"])
    check("session: !0L100,0,0 exchange", s.cmd("tx 21304C3130302C302C300D 250954864"),
          ["rx 3125016 300D", "now 3211822"])
    check("session: until 100 ms", s.cmd("until 100000000"), ["now 100000000"])
    check("session: next = vector end", s.cmd("next"), ["next 155000000"])
    check("session: !0H answered 8 at rest", s.cmd("tx 2130480D 351302088"),
          ["rx 150434030 380D", "now 150520836"])
    check("session: in 1 FE", s.cmd("in 1 FE"), ["ok"])
    s.quit()
    check("quit ends with status 0", s.p.returncode, 0)
    s = Sim()
    check("extension batch named", s.first.split()[2:], ["batch", "batch-stops"])
    s.cmd("baud 115200")
    check("batch: the session's two frames in one exchange",
          s.batch("batch 250781252 21303F0D 250954864 21304C3130302C302C300D"),
          ["rx 434030 302C495038342076332032372E312E323031300D", "now 2083344",
           "rx 3125016 300D", "now 3211822"])
    check("batch-stops: ends after a frame not answered within its D",
          s.batch("batch 1000 2130480D 1000 2130460D"), ["now 3560046"])
    check("malformed command -> error", s.cmd("until 5")[0][:7], "error: ")
    s.quit()


def test_checksums():
    """Manual 12.3.2 and 12.3.3."""
    s = Sim()
    check("12.3.2 !0A100, sums to 4F", cs("!0A100"), "!0A100,4F")
    check("12.3.2 !0%+ -> 0,5C", s.frame("0%+"), "0,5C")
    check("12.3.2 !0A100,4F accepted", s.frame("0A100,4F"), "0,5C")
    check("12.3.2 bad checksum refused", s.frame("0A100,4E")[0], "4")
    pkt = ["0*S,FA", "0C697,30,0,51", "0C692,92,0,54", "0C682,151,0,7F", "0C665,209,0,84",
           "0C645,268,0,87", "0C619,322,0,7F", "0C589,375,0,8D", "0C553,425,0,80",
           "0C515,471,0,7F", "0C471,515,0,7F"]
    check("12.3.3 the manual's packet checksums", [cs("!" + f.rsplit(",", 1)[0])[1:] for f in pkt],
          pkt)
    quiet = [s.frame(f, wait=0) for f in pkt]
    check("12.3.3 no answer inside the packet", quiet, [""] * len(pkt))
    check("12.3.3 !0*E10,4D -> 0,10,E9", s.frame("0*E10,4D"), "0,10,E9")
    t0 = s.now
    s.cmd("until %d" % (s.now + 1_000_000_000))
    mid = s.state()["position"]
    check("12.3.3 moving along the vectors (no stop at the junctions)",
          s.frame(cs("!0SR6")[1:]), cs("0,40"))
    s.cmd("until %d" % (t0 + 8_000_000_000))
    st = s.state()
    check("12.3.3 the packet's 10 vectors ran", st["position"],
          [697 + 692 + 682 + 665 + 645 + 619 + 589 + 553 + 515 + 471,
           30 + 92 + 151 + 209 + 268 + 322 + 375 + 425 + 471 + 515, 0])
    check("12.3.2 !0%-,CF -> 0", s.frame("0%-,CF"), "0")
    check("checksums off again", s.frame("0V1000"), "0")
    s.quit()


def test_answers():
    """Manual 12.6 table of answers, and the commands' own examples."""
    s = Sim()
    check("12.6 !0L1000,0,0 -> 0", s.frame("0L1000,0,0"), "0")
    s.cmd("until %d" % (s.now + 2_000_000_000))
    check("12.5.6 !0NX-1000 (NX100 form)", s.frame("0NX-1000"), "0")
    s.frame("0NY2000")
    s.frame("0NZ50")
    check("12.6 !0PF -> 0,-1000,2000,50", s.frame("0PF"), "0,-1000,2000,50")
    check("12.5.6 !0P -> x,y", s.frame("0P"), "0,-1000,2000")
    check("12.5.6 !0NX0", (s.frame("0NX0"), s.frame("0PF")), ("0", "0,0,2000,50"))
    check("12.5.6 !0NX100", (s.frame("0NX100"), s.frame("0P")), ("0", "0,100,2000"))
    check("12.5.6 !0N", (s.frame("0N"), s.frame("0PF")), ("0", "0,0,0,0"))
    check("12.6 !0SW8,F1 -> 5", s.frame("0SW8,F1"), "5")
    s.frame("0SW2,2B")
    check("12.6 !0SR2 -> 0,2B", s.frame("0SR2"), "0,2B")
    s.frame("0SW2,00")
    # queue full: 64 vectors held (1 executing + 63 queued), the next is refused
    s.frame("0V10")
    got = [s.frame("0C100,20,0") for _ in range(64)]
    check("12.5.2 64 C vectors accepted", set(got), {"0"})
    check("12.5.11 F shows queue full (bit 5) and RUN", s.frame("0F"), "0,60")
    check("12.6 !0C100,20,0 -> 1 (queue full)", s.frame("0C100,20,0"), "1")
    check("12.5.2 L0,0,0 refused (1) while the queue runs", s.frame("0L0,0,0"), "1")
    # halt it: INTA = 1 shows in every answer
    ans = s.frame("0H", wait=900_000_000)
    check("12.5.8 !0H answers 8 after stopping", ans, "8")
    check("12.6 !0V1000 -> 8 (INTA=1)", s.frame("0V1000"), "8")
    check("12.5.11 SR6: INTA, RUN, INTCOM", s.frame("0SR6"), "8,D0")
    check("12.5.8 D deletes, clears INTA", (s.frame("0D"), s.frame("0SR6")), ("0", "0,00"))
    check("12.5.8 G with nothing to go -> 6", s.frame("0G"), "6")
    check("12.5.2 L0,0,0 accepted once the queue is done", s.frame("0L0,0,0"), "0")
    check("12.5.2 !0L1000,1000,20", s.frame("0L1000,1000,20"), "0")
    check("12.5.2 !0C1000,1000,20 queued behind it", s.frame("0C1000,1000,20"), "0")
    check("12.5.2 moving: RUN", s.frame("0SR6"), "0,40")
    s.cmd("until %d" % (s.now + 1_000_000_000))
    p = s.frame("0PF")
    s.cmd("until %d" % (s.now + 1_000_000_000))
    q = s.frame("0PF")
    check("12.5.6 PF changes while moving", p != q, True)
    s.cmd("until %d" % (s.now + 1_000_000_000))
    check("12.5.2 relative vectors add up", s.frame("0PF"), "0,2000,2000,40")
    check("12.5.1 ? version", s.frame("0?"), "0,IP84 v3 27.1.2010")
    check("12.5.1 Q id ddmmrrpp", len(s.frame("0Q").split(",")[1]), 8)
    check("12.6 unknown command -> 3", s.frame("0Y"), "3")
    check("12.6 syntax -> 4", s.frame("0L1,2"), "4")
    check("12.5.2 T25 out of range -> 5", s.frame("0T25"), "5")
    check("12.5.3 V100001 out of range -> 5", s.frame("0V100001"), "5")
    check("12.5.3 !0A50, !0V10000, !0T5", [s.frame("0A50"), s.frame("0V10000"), s.frame("0T5")],
          ["0", "0", "0"])
    check("12.5.3 !0VL25000,25000,30000", s.frame("0VL25000,25000,30000"), "0")
    check("12.5.5 !0XM100 !0XM200", [s.frame("0XM100"), s.frame("0XM200")], ["0", "0"])
    check("11 !0EW01,00", s.frame("0EW01,00"), "0")
    check("12.5.9 ER01", s.frame("0ER01"), "0,00")
    s.frame("0EW10,5A")
    check("12.5.9 EW10,5A then ER10", s.frame("0ER10"), "0,5A")
    check("12.5.10 !0O0,FB (OUT1 on)", (s.frame("0O0,FB"), s.state()["outputs"]), ("0", "FB"))
    check("12.5.10 !0O0,FF", (s.frame("0O0,FF"), s.state()["outputs"]), ("0", "FF"))
    s.cmd("in 1 FD")
    check("12.5.11 I1 reads the port", s.frame("0I1"), "0,FD")
    s.cmd("in 1 FF")
    # index and repeat (12.5.12)
    n = int(s.frame("0@").split(",")[1])
    s.frame("0SR6")
    s.frame("0SR6")
    check("12.5.12 @ counts commands modulo 256", int(s.frame("0@").split(",")[1]), (n + 2) % 256)
    pf = s.frame("0PF")
    check("12.5.12 > repeats the last answer", s.frame("0>"), pf)
    check("another address is not answered", s.frame("3SR6", wait=10_000_000), "")
    # watchdog: a frame that stops half way
    s.cmd("tx 2130504600")
    check("12.6 watchdog answers 2", s.until(s.now + 500_000_000), "2")
    s.quit()


def test_keep_restore():
    """Manual 12.5.8, the KEEP/RESTORE example, step by step."""
    s = Sim()
    s.frame("0V2000")
    s.frame("0C5000,0,0")
    s.frame("0C5000,0,0")
    s.frame("0C5000,0,0")
    s.cmd("until %d" % (s.now + 1_000_000_000))
    check("!0H zastaví vektor", s.frame("0H", wait=900_000_000), "8")
    p = s.frame("0P")
    x = int(p.split(",")[1])
    check("!0P where it stopped (mid-run)", 0 < x < 15000, True)
    check("!0SR4", s.frame("0SR4"), "8,00")
    check("!0SR5", s.frame("0SR5"), "8,00")
    check("!0SR6 INTA RUN INTCOM", s.frame("0SR6"), "8,D0")
    check("!0SW0,1A", s.frame("0SW0,1A"), "8")
    check("!0SW1,3F", s.frame("0SW1,3F"), "8")
    check("!0K", s.frame("0K"), "0")
    check("!0L0,0,-1000", s.frame("0L0,0,-1000"), "0")
    s.cmd("until %d" % (s.now + 1_500_000_000))
    check("after the lift", s.frame("0PF"), "0,%d,0,-1000" % x)
    check("!0L0,0,1000", s.frame("0L0,0,1000"), "0")
    s.cmd("until %d" % (s.now + 1_500_000_000))
    check("!0R", s.frame("0R"), "8")
    check("!0V500", s.frame("0V500"), "8")
    check("!0XA", s.frame("0XA"), "8")
    check("!0SW0,A2", s.frame("0SW0,A2"), "8")
    check("!0SW1,78", s.frame("0SW1,78"), "8")
    check("!0G", s.frame("0G"), "0")
    s.cmd("until %d" % (s.now + 30_000_000_000 // 30 * 30))
    for _ in range(40):
        s.cmd("until %d" % (s.now + 1_000_000_000))
    check("the rest of the queue done", s.frame("0PF"), "0,15000,0,0")
    check("SR6 idle", s.frame("0SR6"), "0,00")
    s.quit()


def test_interrupt_and_reference():
    """12.5.11 interrupts stop the motion; 12.5.7 W with the manual's example."""
    s = Sim()
    s.frame("0SW0,01")
    s.frame("0L5000,0,0")
    s.cmd("until %d" % (s.now + 500_000_000))
    s.cmd("in 1 FE")
    check("interrupt: INTA in the answer", s.frame("0SR6")[0], "8")
    s.cmd("until %d" % (s.now + 500_000_000))
    check("interrupt: ST4 names INTR0", s.frame("0SR4"), "8,01")
    check("interrupt: the axis stopped", s.frame("0SR6"), "8,C0")
    s.cmd("in 1 FF")
    check("interrupt: G resumes", s.frame("0G"), "0")
    for _ in range(10):
        s.cmd("until %d" % (s.now + 1_000_000_000))
    check("interrupt: the vector completed", s.frame("0PF"), "0,5000,0,0")
    s.frame("0SW0,00")
    s.cmd("switch Y -1500")
    ans = s.frame("0WY,-20000,1000,2000,500", wait=900_000_000)
    check("W answers only when done (not within 0.9 s)", ans, "")
    ans = s.until(s.now + 2_000_000_000)
    check("W !0WY,-20000,1000,2000,500 answers 0", ans, "0")
    st = s.state()
    check("W: Y counter zeroed", st["position"][1], 0)
    check("W: Y released one step back from the switch", st["physical"][1], -1499)
    check("W: the run reached the switch", st["excursion"][1][0], -1500)
    s.quit()


def test_reset():
    """12.4: the state after J (and after power-on)."""
    s = Sim()
    s.frame("0%+")
    s.frame(cs("!0V5000")[1:])
    s.frame(cs("!0L100,0,0")[1:])
    s.cmd("until %d" % (s.now + 1_000_000_000))
    s.frame(cs("!0SW0,07")[1:])
    s.frame(cs("!0O0,00")[1:])
    check("J answers (0 with its checksum)", s.frame(cs("!0J")[1:]), "0,5C")
    check("deaf while restarting", s.frame("0SR6", wait=100_000_000), "")
    s.cmd("until %d" % (s.now + 2_100_000_000))
    st = s.state()
    check("J: ST0..ST6 = 00", st["status"], ["00"] * 7)
    check("J: counters zeroed, axes stay", (st["position"], st["physical"]),
          ([0, 0, 0], [100, 0, 0]))
    check("J: O0,FF", st["outputs"], "FF")
    check("J: checksums off", s.frame("0SR0"), "0,00")
    check("J: index restarts at 0 (one SR0 since)", s.frame("0@"), "0,1")
    check("J: modal A20 V1000 $512", (st["modal"]["A"], st["modal"]["V"], st["modal"]["$"]),
          (20, 1000, 512))
    s.frame("0SW0,05")
    check("power-on", s.cmd("power-on"), ["ok"])
    s.cmd("until %d" % (s.now + 2_100_000_000))
    st = s.state()
    check("power-on: reset state", (st["status"], st["position"], st["checksums"]),
          (["00"] * 7, [0, 0, 0], False))
    check("power-on: @ reads 0", s.frame("0@"), "0,0")
    s.quit()


def test_models():
    for model, top in (("GVE84-15", 15000), ("GVE84-50", 50000), ("GVE84-100", 100000)):
        s = Sim("--model", model)
        check("%s: V%d accepted, V%d refused" % (model, top, top + 1),
              (s.frame("0V%d" % top), s.frame("0V%d" % (top + 1))), ("0", "5"))
        check("%s: profile" % model, s.state()["profile"], model)
        s.quit()
    s = Sim("--address", "5")
    check("--address 5 answers !5, not !0", (s.frame("5SR6"), s.frame("0SR6", wait=10**7)),
          ("0,00", ""))
    s.quit()


def main():
    for t in (test_session, test_checksums, test_answers, test_keep_restore,
              test_interrupt_and_reference, test_reset, test_models):
        print("--", t.__doc__.strip().splitlines()[0] if t.__doc__ else t.__name__)
        t()
    print("%d FAIL" % len(FAILS) if FAILS else "ALL PASS")
    return 1 if FAILS else 0


if __name__ == "__main__":
    sys.exit(main())
