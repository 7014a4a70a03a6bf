#!/usr/bin/env python3
"""Self-test of sim.py: the manual's worked examples, the reset state and the
main behaviours, each driven through the co-simulation protocol
(given/cosim.md) exactly as the suite would drive it.  Prints PASS/FAIL per
check; exit status 0 when all pass."""
import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
NS = 1_000_000_000
MS = 1_000_000
B = round(10 * NS / 115200)          # byte time at 115200 baud

results = []


def check(name, ok, detail=""):
    results.append(ok)
    print("%s  %s%s" % ("PASS" if ok else "FAIL", name,
                        "" if ok or not detail else "   [%s]" % detail))


class Sim:
    """sim.py --cosim driven over a pipe."""

    def __init__(self, *args):
        self.p = subprocess.Popen([sys.executable, os.path.join(HERE, 'sim.py'), '--cosim'] + list(args),
                                  stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, bufsize=1)
        self.first = self.p.stdout.readline().strip()
        self.now = 0

    def cmd(self, line):
        """Send one protocol line; returns its reply lines (last one final)."""
        self.p.stdin.write(line + "\n")
        self.p.stdin.flush()
        lines = []
        while True:
            r = self.p.stdout.readline()
            if not r:
                raise RuntimeError("sim.py ended after %r" % line)
            r = r.rstrip("\n")
            lines.append(r)
            if r.startswith("now "):
                self.now = int(r.split()[1])
                return lines
            if not r.startswith("rx "):
                return lines

    def frame(self, text, wait=NS, cr=True):
        """Send a frame and wait (at most `wait` ns after its bytes) for the
        answer.  Returns (answer text or None, instant of its first byte,
        instant of its CR, instant the frame's CR reached the unit)."""
        data = (text + ("\r" if cr else "")).encode('latin-1')
        end = self.now + len(data) * B
        lines = self.cmd("tx %s %d" % (data.hex().upper(), end + wait))
        got = []
        for r in lines:
            if r.startswith("rx "):
                _, t, hx = r.split()
                t = int(t)
                for i, byte in enumerate(bytes.fromhex(hx)):
                    got.append((t + i * B, byte))
        if not got or got[-1][1] != 0x0D:
            return None, None, None, end
        return (bytes(b for _, b in got[:-1]).decode('latin-1'), got[0][0], got[-1][0], end)

    def ask(self, text, wait=NS):
        return self.frame(text, wait)[0]

    def until(self, t):
        return self.cmd("until %d" % t)

    def wait(self, ns):
        """Let virtual time run (in pieces of at most 1 s, as the suite does)."""
        target = self.now + ns
        while self.now < target:
            self.until(min(target, self.now + NS))

    def state(self):
        return json.loads(self.cmd("state")[-1])

    def wait_idle(self, limit=60 * NS, addr=0):
        """Poll F until RUN = 0 and no stop ramp (as a host would)."""
        start = self.now
        while self.now - start < limit:
            a = self.ask("!%dF" % addr)
            if a and (int(a.split(",")[1], 16) & 0x41) == 0:
                return True
            self.wait(20 * MS)
        return False

    def close(self):
        try:
            self.p.stdin.write("quit\n")
            self.p.stdin.flush()
        except BrokenPipeError:
            pass
        return self.p.wait(timeout=10)


def main():
    # ------------------------------------------------------------ handshake
    s = Sim()
    check("handshake: first line is 'cosim 1 ...'", s.first.split()[:2] == ["cosim", "1"], s.first)
    check("baud 115200 -> ok", s.cmd("baud 115200") == ["ok"])
    st = s.state()
    check("state: JSON with the rig's keys",
          all(k in st for k in ("position", "physical", "excursion", "status", "outputs",
                                "spindle", "inputs")), str(st))

    # ---------------------------------------------------------- reset state
    check("reset: ST0..ST6 = 00 (state)", st["status"] == ["00"] * 7, str(st["status"]))
    for n in range(7):
        check("reset: SR%d -> 0,00" % n, s.ask("!0SR%d" % n) == "0,00")
    check("reset: PF -> 0,0,0,0 (N: counters zeroed)", s.ask("!0PF") == "0,0,0,0")
    check("reset: P -> 0,0,0", s.ask("!0P") == "0,0,0")
    check("reset: F -> 0,00 (queue empty)", s.ask("!0F") == "0,00")
    st = s.state()
    check("reset: MF (1/16 steps), MD (half current)",
          st["microstep"] == "F" and st["current"] == "D")
    check("reset: A20 V1000 $512 B50000", st["modal"]["A"] == 20 and st["modal"]["V"] == 1000
          and st["modal"]["$"] == 512 and st["modal"]["B"] == 50000, str(st["modal"]))
    check("reset: O0,FF outputs off", st["outputs"] == "FF")
    check("reset: index 0 (@ after 7 SR, 3 P/F -> 10)", s.ask("!0@") == "0,10")

    # ----------------------------------------- answer timing and cosim session
    s = Sim()
    s.cmd("baud 115200")
    a, t1, tcr, end = s.frame("!0?")
    check("? -> 0,IP54 v3 21.12.2007", a == "0,IP54 v3 21.12.2007", a)
    check("answer starts at once: first byte one byte time after the CR",
          t1 == end + B, "%s vs %s" % (t1, end + B))
    a = s.ask("!0Q")
    check("Q -> 0,ddmmrrpp (8 digits)", a is not None and a[:2] == "0," and len(a) == 10
          and a[2:].isdigit(), a)
    a, t1, tcr, end = s.frame("!0L100,0,0")
    check("manual: !0L1000,0,0 style vector -> 0", a == "0", a)
    s.until(100 * MS)
    nx = s.cmd("next")[-1]
    check("next: vector of 100 pulses at V1000 A20 ends at 155 ms (T5 dwell + 150 ms)",
          nx == "next 155000000", nx)
    p1 = s.ask("!0PF")
    s.wait(10 * MS)
    p2 = s.ask("!0PF")
    check("PF changes while the axis moves", p1 != p2 and p1.startswith("0,") and p2.startswith("0,"),
          "%s %s" % (p1, p2))
    s2 = Sim()
    s2.cmd("baud 115200")
    s2.frame("!0?")
    s2.frame("!0L100,0,0")
    s2.until(100 * MS)
    a, t1, tcr, end = s2.frame("!0H", 251 * MS)
    check("H answers 8 only after the 50 ms brake ramp (cosim.md session: 150434030)",
          a == "8" and t1 == 150434030, "%s at %s" % (a, t1))
    sr6 = s2.ask("!0SR6")
    check("after H while running: SR6 = D0 (INTA, RUN, INTCOM)", sr6 == "8,D0", sr6)
    s2.close()

    # -------------------------------------- manual: the exact example frames
    s = Sim()
    a = s.ask("!0L1000,0,0")
    check("manual: !0L1000,0,0 -> 0", a == "0", a)
    check("the vector runs: SR6 -> 0,40 (RUN)", s.ask("!0SR6") == "0,40")
    s.wait_idle()
    check("after the vector: PF -> 0,1000,0,0, SR6 -> 0,00",
          s.ask("!0PF") == "0,1000,0,0" and s.ask("!0SR6") == "0,00")
    s.close()

    # ---------------------------------------------- manual: !1PF, !1SR2 at address 1
    s = Sim("--address", "1")
    check("address 1: !0 frame is not answered", s.ask("!0V1000", 50 * MS) is None)
    s.ask("!1L-1000,2000,50")
    s.wait_idle(addr=1)
    a = s.ask("!1PF")
    check("manual: !1PF -> 0,-1000,2000,50", a == "0,-1000,2000,50", a)
    s.ask("!1SW2,2B")
    a = s.ask("!1SR2")
    check("manual: !1SR2 -> 0,2B", a == "0,2B", a)
    a = s.ask("!1SW8,F1")
    check("manual: !0SW8,F1 -> 5 (parameter out of range)", a == "5", a)
    s.close()

    # -------------------------------------------------- manual: queue full -> 1
    s = Sim()
    s.ask("!0V40")
    answers = [s.ask("!0C100,20,0") for _ in range(96)]
    check("96 CONT vectors accepted (1 running + 95 queued)", answers == ["0"] * 96,
          str(set(answers)))
    f = s.ask("!0F")
    check("F bit 5: queue full (F -> 0,60)", f == "0,60", f)
    a = s.ask("!0C100,20,0")
    check("manual: !0C100,20,0 -> 1 (queue full, vector not accepted)", a == "1", a)
    a = s.ask("!0L1,0,0")
    check("L onto a non-empty queue -> 1", a == "1", a)
    check("D while running -> 7", s.ask("!0D") == "7")
    check("N while running -> 7", s.ask("!0N") == "7")
    check("M4 while running -> 7", s.ask("!0M4") == "7")
    check("K while running -> 7", s.ask("!0K") == "7")
    check("XU while running -> 0", s.ask("!0XU") == "0")
    check("XD while running -> 0", s.ask("!0XD") == "0")
    check("G with INTA=0 -> 6", s.ask("!0G") == "6")
    a = s.ask("!0H", NS)
    check("H during a slow CONT queue -> 8", a == "8", a)
    check("D after H deletes the queue -> 0", s.ask("!0D") == "0")
    check("after D: SR6 -> 0,00", s.ask("!0SR6") == "0,00")
    s.close()

    # --------------------------------------------- manual: !0V1000 -> 8 (INTA=1)
    s = Sim()
    check("H at rest answers at once -> 8", s.ask("!0H") == "8")
    check("H at rest: SR6 = 90 (INTA, INTCOM; RUN = 0)", s.ask("!0SR6") == "8,90")
    a = s.ask("!0V1000")
    check("manual: !0V1000 -> 8 (OK, but interrupted INTA=1)", a == "8", a)
    check("G with INTA=1 and nothing queued -> 6, INTA cleared", s.ask("!0G") == "6"
          and s.ask("!0SR6") == "0,00")
    s.close()

    # ----------------------------------------- manual: micro-steps, M4 example
    s = Sim()
    s.ask("!0M4")
    s.ask("!0L100,100,100")
    s.wait_idle()
    a = s.ask("!0PF")
    check("manual: M4, L100,100,100, PF -> 0,400,400,400", a == "0,400,400,400", a)
    s.ask("!0MF")
    s.ask("!0N")
    s.ask("!0L1001,500,399")
    s.wait_idle()
    a = s.ask("!0PF")
    check("manual: stopped at PF = 0,1001,500,399", a == "0,1001,500,399", a)
    s.ask("!0L-1,0,1")
    s.wait_idle()
    a = s.ask("!0PF")
    check("manual: L-1,0,1 -> PF = 0,1000,500,400", a == "0,1000,500,400", a)
    check("manual: M4 after rounding -> 0", s.ask("!0M4") == "0")
    s.close()

    # ------------------------------------------ manual: L0,0,0 at the queue end
    s = Sim()
    for v in ("C2000,0,0", "C2000,100,0", "C2000,200,0"):
        s.ask("!0" + v)
    first = s.ask("!0L0,0,0")
    tries = 1
    while s.ask("!0L0,0,0") != "0" and tries < 1000:
        tries += 1
        s.wait(50 * MS)
    pf = s.ask("!0PF")
    check("manual: L0,0,0 answers 1 while the queue runs, then 0 when it is done",
          first == "1" and tries > 1 and pf == "0,6000,300,0", "%s %d %s" % (first, tries, pf))
    s.close()

    # -------------------------------------- manual: KEEP / RESTORE walkthrough
    s = Sim()
    s.ask("!0L4000,0,0")
    s.wait(500 * MS)
    a = s.ask("!0H", NS)
    check("KEEP example: !H stops the vector -> 8", a == "8", a)
    p = s.ask("!0P")
    x_h = int(p.split(",")[1])
    check("KEEP example: !P gives where it stopped (0 < x < 4000)", 0 < x_h < 4000, p)
    check("KEEP example: SR4, SR5 -> 8,00 (no input interrupt), SR6 -> 8,D0",
          s.ask("!0SR4") == "8,00" and s.ask("!0SR5") == "8,00" and s.ask("!0SR6") == "8,D0")
    check("KEEP example: !SW0,1A !SW1,3F", s.ask("!0SW0,1A") == "8" and s.ask("!0SW1,3F") == "8")
    check("KEEP example: !K -> 0 (ST4..ST6 cleared)", s.ask("!0K") == "0")
    check("after K: SR6 -> 0,00", s.ask("!0SR6") == "0,00")
    check("KEEP example: !L0,0,-1000 lifts the tool -> 0", s.ask("!0L0,0,-1000") == "0")
    s.wait_idle()
    a = s.ask("!0L0,0,1000")
    check("KEEP example: !L0,0,1000 lowers it -> 0", a == "0", a)
    s.wait_idle()
    check("KEEP example: !R restores the queue -> 8 (INTA restored)", s.ask("!0R") == "8")
    check("after R: SR6 -> 8,D0", s.ask("!0SR6") == "8,D0")
    check("KEEP example: !V500 !XA", s.ask("!0V500") == "8" and s.ask("!0XA") == "8")
    check("KEEP example: !SW0,A2 !SW1,78", s.ask("!0SW0,A2") == "8" and s.ask("!0SW1,78") == "8")
    t0 = s.now
    check("KEEP example: !G continues -> 0", s.ask("!0G") == "0")
    s.wait_idle()
    pf = s.ask("!0PF")
    check("KEEP example: the rest of the vector is done -> PF 0,4000,0,0", pf == "0,4000,0,0", pf)
    dur = (s.now - t0) / NS
    check("KEEP example: the rest ran at the new speed V500 (>= %.2f s)" % ((4000 - x_h) / 500),
          dur >= (4000 - x_h) / 500, "%.3f s" % dur)
    check("after the queue: SR6 -> 0,00", s.ask("!0SR6") == "0,00")
    s.close()

    # ----------------------------------------------------- interrupts (rig)
    s = Sim()
    s.ask("!0SW0,01")
    s.ask("!0L3000,0,0")
    s.wait(300 * MS)
    check("rig: in 1 FE -> ok", s.cmd("in 1 FE") == ["ok"])
    sr6 = s.ask("!0SR6")
    check("interrupt INTR0 (active low): braking, SR6 = C1 (INTA, RUN, STOP)", sr6 == "8,C1", sr6)
    s.wait_idle()
    check("interrupt: SR4 -> 8,01 (cause INTR0)", s.ask("!0SR4") == "8,01")
    check("interrupt: I1 -> 8,FE", s.ask("!0I1") == "8,FE")
    x = int(s.ask("!0PF").split(",")[1])
    check("interrupt stopped the vector on its ramp (0 < x < 3000)", 0 < x < 3000, str(x))
    check("G resumes -> 0", s.ask("!0G") == "0")
    s.wait_idle()
    pf = s.ask("!0PF")
    check("after G the vector is finished -> PF 0,3000,0,0", pf == "0,3000,0,0", pf)
    st = s.state()
    check("state: physical and excursion follow the motion",
          st["physical"] == [3000, 0, 0] and st["excursion"][0] == [0, 3000], str(st["physical"]))
    s.close()

    # ------------------------------------------- motion: dwell, CONT chain, XU
    s = Sim()
    s.ask("!0L100,0,0")
    s.wait_idle()
    nx = s.cmd("next")[-1]
    check("next none when the unit is idle", nx == "next none", nx)
    s.until(1 * NS)
    a, t1, tcr, t_acc = s.frame("!0L100,0,0")
    nx = int(s.cmd("next")[-1].split()[1])
    check("L from long rest: starts at its CR, 150 ms trapezoid", nx - t_acc == 150 * MS,
          str(nx - t_acc))
    s.until(nx)
    a, t1, tcr, end = s.frame("!0L100,0,0")
    nx2 = int(s.cmd("next")[-1].split()[1])
    check("T5 dwell: an L right after rest starts 5 ms after the previous one ended",
          nx2 == nx + 5 * MS + 150 * MS, "%d" % (nx2 - nx))
    s.wait_idle()
    s.ask("!0T20")
    s.wait(NS)
    # two L of 100 vs. a C chain of 2 x 100: the chain does not stop between them
    s.ask("!0C100,0,0")
    s.ask("!0C100,0,0")
    t0 = s.now
    n1 = int(s.cmd("next")[-1].split()[1])
    s.until(n1)
    n2 = int(s.cmd("next")[-1].split()[1])
    check("C chain: 200 pulses without stopping in 250 ms (B50000: no brake between)",
          n2 - t0 <= 251 * MS and n2 - t0 >= 245 * MS, "%d" % (n2 - t0))
    s.wait_idle()
    s.ask("!0B100")
    s.ask("!0C1000,0,0")
    s.ask("!0C1000,0,0")
    s.wait_idle()
    pf = s.ask("!0PF")
    check("C chain with B100 reaches PF 0,2500,0,0", pf == "0,2500,0,0", pf)
    s.ask("!0B50000")
    s.ask("!0V1000")
    s.ask("!0L2000,0,0")
    s.wait(300 * MS)
    check("XU while running -> 0", s.ask("!0XU") == "0")
    t0 = s.now
    s.wait_idle()
    # without XU: 2000 pulses at 1000/s take 2.05 s from start; with XU (1062/s) less
    check("XU makes the running vector faster (ends before 2.05 s)", s.now < 2055 * MS + t0 - 300 * MS,
          "%d" % s.now)
    s.close()

    # --------------------------------------------------- batch extension
    s = Sim()
    frames = ["!0SR6", "!0V2000", "!0@"]
    args = " ".join("%d %s" % (NS, (f + "\r").encode().hex().upper()) for f in frames)
    lines = s.cmd("batch " + args)
    nows = [r for r in lines if r.startswith("now")]
    while len(nows) < 3:
        r = s.p.stdout.readline().rstrip("\n")
        lines.append(r)
        if r.startswith("now"):
            nows.append(r)
    check("batch: three frames, three 'now' lines", len(nows) == 3, str(lines[-3:]))
    s.now = int(nows[-1].split()[1])
    check("batch: the frames ran (@ -> 0,2)", s.ask("!0@") == "0,2")
    check("SW6,80 at rest sets INTA (SR6 -> 8,80)", s.ask("!0SW6,80") == "8" and s.ask("!0SR6") == "8,80")
    check("SW6,00 clears it", s.ask("!0SW6,00") == "0" and s.ask("!0SR6") == "0,00")
    s.cmd("in 1 FE")
    check("input already active, then enabled by SW0: interrupt at its activation",
          s.ask("!0SW0,01") == "8" and s.ask("!0SR4") == "8,01")
    check("G at rest clears it; the input still active does not interrupt again",
          s.ask("!0G") == "6" and s.ask("!0SR4") == "0,00" and s.ask("!0SR6") == "0,00")
    s.ask("!0SW2,01")
    check("polarity 1 (ST2 bit 0): input at 0 is inactive, going to 1 interrupts",
          s.cmd("in 1 FF") == ["ok"] and s.ask("!0SR4") == "8,01")
    s.close()

    # --------------------------------------------------- snapshot extension
    s = Sim()
    check("first line names the snapshot extension", "snapshot" in s.first.split()[2:], s.first)
    check("restore before any snapshot -> error", s.cmd("restore")[-1].startswith("error:"))
    s.ask("!0V2000")
    check("snapshot -> ok", s.cmd("snapshot") == ["ok"])
    s.ask("!0V3000")
    s.ask("!0L100,0,0")
    s.wait(NS)
    before = s.now
    r = s.cmd("restore")
    check("restore -> now T, the clock not going back", r == ["now %d" % before], str(r))
    st = s.state()
    check("after restore: the unit as kept (V2000, no motion, index 1)",
          st["modal"]["V"] == 2000 and st["position"] == [0, 0, 0] and st["index"] == 1, str(st))
    s.close()

    # -------------------------------------------------------- errors, index
    s = Sim()
    check("unknown command !0Z -> 3", s.ask("!0Z") == "3")
    check("syntax !0V -> 4", s.ask("!0V") == "4")
    check("syntax !0L1,2 -> 4", s.ask("!0L1,2") == "4")
    check("range !0V39 -> 5", s.ask("!0V39") == "5")
    check("range !0V50001 -> 5", s.ask("!0V50001") == "5")
    check("range !0T25 -> 5", s.ask("!0T25") == "5")
    check("range !0L65536,0,0 -> 5", s.ask("!0L65536,0,0") == "5")
    check("range !0SR7 -> 5", s.ask("!0SR7") == "5")
    check("range !0M3 -> 5", s.ask("!0M3") == "5")
    check("@ counts every command (9 so far)", s.ask("!0@") == "0,9")
    check("> repeats the last answer (0,9)", s.ask("!0>") == "0,9")
    check("O0,FE -> 0, state outputs FE", s.ask("!0O0,FE") == "0" and s.state()["outputs"] == "FE")
    check("EW10,5A -> 0; ER10 -> 0,5A", s.ask("!0EW10,5A") == "0" and s.ask("!0ER10") == "0,5A")
    check("ER11 (never written) -> 0,FF", s.ask("!0ER11") == "0,FF")
    s.cmd("in 2 7F")
    check("I2 reads the rig's port 2 -> 0,7F", s.ask("!0I2") == "0,7F")
    # watchdog
    a, t1, tcr, end = s.frame("!0V100", 300 * MS, cr=False)
    check("watchdog: unfinished frame answered 2 at 100 ms after its '!'",
          a == "2" and t1 == end - 5 * B + 100 * MS + B, "%s %s" % (a, t1))
    check("noise without '!' is ignored", s.ask("V100", 50 * MS) is None)
    # J
    s.ask("!0L100,0,0")
    s.wait_idle()
    check("J -> 0", s.ask("!0J") == "0")
    check("during the 2 s restart the unit is deaf", s.ask("!0SR6", 500 * MS) is None)
    s.wait(2 * NS)
    check("after J: PF 0,0,0,0, EEPROM kept, O0,FF",
          s.ask("!0PF") == "0,0,0,0" and s.ask("!0ER10") == "0,5A" and s.state()["outputs"] == "FF")
    check("after J: the axes stayed where they were (physical 100)", s.state()["physical"][0] == 100)
    check("after J: @ -> 0,2", s.ask("!0@") == "0,2")
    # power-on by the rig
    s.ask("!0V2000")
    check("rig power-on -> ok", s.cmd("power-on") == ["ok"])
    check("power-on: deaf for 2 s", s.ask("!0SR6", NS) is None)
    s.wait(NS)
    st = s.state()
    check("power-on: reset state (V1000, ST 00, counters 0, queue 0)",
          st["modal"]["V"] == 1000 and st["status"] == ["00"] * 7 and st["position"] == [0, 0, 0]
          and st["queue"] == 0, str(st))
    check("power-on: SR6 answered again", s.ask("!0SR6") == "0,00")
    check("protocol: until before now -> error", s.cmd("until 0")[-1].startswith("error:"))
    check("protocol: unknown command -> error", s.cmd("fly")[-1].startswith("error:"))
    check("protocol: quit ends with status 0", s.close() == 0)

    n_fail = results.count(False)
    print("%d checks, %d passed, %d failed" % (len(results), len(results) - n_fail, n_fail))
    return 0 if n_fail == 0 else 1


if __name__ == '__main__':
    sys.exit(main())
