#!/usr/bin/env python3
"""Runs the GVE114 manual's own worked examples against sim.py over the
co-simulation protocol (cosim.md).  Prints PASS/FAIL per check, exit 0 when
all pass.   usage: python3 selftest.py [--model GVE114-500]"""
import subprocess, sys, os, json

HERE = os.path.dirname(os.path.abspath(__file__))
RESULTS = []


def check(name, ok, detail=""):
    RESULTS.append(ok)
    print("%s  %s%s" % ("PASS" if ok else "FAIL", name, ("  (" + detail + ")") if detail and not ok else ""))


def csum(s):
    return "%02X" % (sum(s.encode()) & 0xFF)


class Cosim:
    def __init__(self, *args):
        self.p = subprocess.Popen([sys.executable, os.path.join(HERE, "sim.py"), "--cosim"] + list(args),
                                  stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
        self.first = self.p.stdout.readline().strip()
        self.now = 0

    def cmd(self, line):
        self.p.stdin.write(line + "\n")
        self.p.stdin.flush()
        out = []
        while True:
            l = self.p.stdout.readline()
            if not l:
                raise RuntimeError("simulator ended")
            l = l.strip()
            out.append(l)
            if not l.startswith("rx "):
                break
        rx = b""
        for l in out[:-1]:
            parts = l.split()
            rx += bytes.fromhex(parts[2])
        if out[-1].startswith("now "):
            self.now = int(out[-1].split()[1])
        return rx, out[-1]

    def frame(self, text, wait_ns=1_000_000_000):
        """send one frame, wait for its answer (up to wait_ns); answer text without CR or None"""
        data = (text + "\r").encode()
        b = round(1e10 / 115200)
        end = self.now + len(data) * b
        rx, last = self.cmd("tx %s %d" % (data.hex().upper(), end + wait_ns))
        if not rx:
            return None
        return rx.decode().rstrip("\r")

    def until(self, dt):
        return self.cmd("until %d" % (self.now + dt))

    def wait_answer(self, max_ns=20_000_000_000):
        rx = b""
        t = 0
        while t < max_ns and not rx.endswith(b"\r"):
            r, _ = self.until(1_000_000_000)
            rx += r
            t += 1_000_000_000
        return rx.decode().rstrip("\r") if rx else None

    def state(self):
        _, l = self.cmd("state")
        return json.loads(l)

    def idle(self):
        for _ in range(600):
            a = self.frame("!0SR6")
            if a is not None and int(a.split(",")[1], 16) & 0x40 == 0:
                return True
            self.until(500_000_000)
        return False

    def close(self):
        try:
            self.p.stdin.write("quit\n")
            self.p.stdin.flush()
        except Exception:
            pass
        self.p.wait(timeout=10)


def reset_state_checks(s, tag):
    st = s.state()
    check(tag + ": state status ST0..ST6 = 00", st["status"] == ["00"] * 7, str(st["status"]))
    check(tag + ": outputs O0,FF", st["outputs"] == "FF", st["outputs"])
    check(tag + ": A20 V1000 $512 B50000",
          (st["modal"]["A"], st["modal"]["V"], st["modal"]["$"], st["modal"]["B"]) == (20, 1000, 512, 50000),
          str(st["modal"]))
    check(tag + ": checksums off", st["checksums"] is False)
    check(tag + ": queue empty, index 0", st["queue"] == 0 and st["index"] == 0)
    a = s.frame("!0@")
    check(tag + ": !0@ -> 0,0 (index 0)", a == "0,0", repr(a))
    for n in range(7):
        a = s.frame("!0SR%d" % n)
        check(tag + ": !0SR%d -> 0,00" % n, a == "0,00", repr(a))
    a = s.frame("!0PF")
    check(tag + ": !0PF -> 0,0,0,0 (N: counters zeroed)", a == "0,0,0,0", repr(a))


def main():
    model = "GVE114-500"
    if "--model" in sys.argv:
        model = sys.argv[sys.argv.index("--model") + 1]
    rate = {"GVE114-500": 500, "GVE114-200": 200, "GVE114-125": 125, "GVE114-50": 50}[model]
    s = Cosim("--model", model)
    check("handshake 'cosim 1'", s.first.split()[:2] == ["cosim", "1"], s.first)
    _, l = s.cmd("baud 115200")
    check("baud 115200 -> ok", l == "ok")
    st = s.state()
    check("state profile", st["profile"] == model)
    reset_state_checks(s, "power-up reset state (13.5)")

    # 13.6.1 identification; 13.2 program string
    a = s.frame("!0?")
    check("!0? -> version IP114/%d x16 16.9.2018 (13.2)" % rate, a == "0,IP114/%d x16 16.9.2018" % rate, repr(a))
    a = s.frame("!0Q")
    check("!0Q -> 8 digits ddmmrrpp (25022504)", a is not None and a.startswith("0,") and len(a) == 10
          and a[2:].isdigit(), repr(a))

    # 13.3.2 checksum arithmetic examples
    check("checksum !0A100, = 0x14F -> 4F", csum("!0A100,") == "4F")
    check("checksum !0%-, -> CF", csum("!0%-,") == "CF")
    check("checksum answer 0, -> 5C", csum("0,") == "5C")
    packet = [("!0*S", "FA"), ("!0C697,30,0", "51"), ("!0C692,92,0", "54"), ("!0C682,151,0", "7F"),
              ("!0C665,209,0", "84"), ("!0C645,268,0", "87"), ("!0C619,322,0", "7F"),
              ("!0C589,375,0", "8D"), ("!0C553,425,0", "80"), ("!0C515,471,0", "7F"),
              ("!0C471,515,0", "7F"), ("!0*E10", "4D")]
    for f, c in packet:
        check("checksum %s,%s (13.4)" % (f, c), csum(f + ",") == c, csum(f + ","))
    check("checksum answer 0,10,E9 (13.4)", csum("0,10,") == "E9")

    # checksum mode on/off
    a = s.frame("!0%+")
    check("!0%+ -> 0,5C (answer already with sum)", a == "0,5C", repr(a))
    a = s.frame("!0A100,4F")
    check("!0A100,4F accepted -> 0,5C", a == "0,5C", repr(a))
    a = s.frame("!0A100,00")
    check("bad checksum -> not executed, error reported", a is not None and a[0] != "0", repr(a))
    # 13.4 packet
    a = s.frame("!0*S,FA", 20_000_000)
    check("packet !0*S,FA -> no answer until the end", a is None, repr(a))
    ok = True
    for f, c in packet[1:-1]:
        a = s.frame(f + "," + c, 20_000_000)
        ok = ok and a is None
    check("packet vectors -> no answers inside the packet", ok)
    a = s.frame("!0*E10,4D")
    check("packet end !0*E10,4D -> 0,10,E9", a == "0,10,E9", repr(a))
    a = s.frame("!0%-,CF")
    check("!0%-,CF -> 0 (answer without sum)", a == "0", repr(a))
    check("packet vectors run to the end", s.idle())
    a = s.frame("!0PF")
    check("packet moved X by 6128, Y by 2858 (sum of its 10 vectors)", a == "0,6128,2858,0", repr(a))

    # 13.8 answers table
    a = s.frame("!0N")
    a = s.frame("!0L1000,0,0")
    check("!0L1000,0,0 -> 0", a == "0", repr(a))
    check("L vector runs", s.idle())
    a = s.frame("!0PF")
    check("after L1000,0,0 PF -> 0,1000,0,0", a == "0,1000,0,0", repr(a))
    s.frame("!0NX-1000"); s.frame("!0NY2000"); s.frame("!0NZ50")
    a = s.frame("!0PF")
    check("!0PF -> 0,-1000,2000,50 (13.8)", a == "0,-1000,2000,50", repr(a))
    a = s.frame("!0NX0")
    check("!0NX0 -> 0 (13.6.6)", a == "0", repr(a))
    a = s.frame("!0NX100"); b = s.frame("!0PF")
    check("!0NX100 sets X counter to 100", a == "0" and b == "0,100,2000,50", repr((a, b)))
    a = s.frame("!0N"); b = s.frame("!0PF")
    check("!0N zeroes the counters", b == "0,0,0,0", repr(b))
    # queue full: C vector not accepted -> 1
    s.frame("!0V10")
    b = round(1e10 / 115200)
    lines = []
    for i in range(2048):
        d = ("!0C100,20,0\r").encode()
        lines.append("tx %s %d" % (d.hex(), 0))
    ok = True
    for i in range(2048):
        a = s.frame("!0C100,20,0", 5_000_000)
        if a != "0":
            ok = False
            break
    check("2048 C vectors accepted (buffer for 2048)", ok, "vector %d answered %r" % (i, a))
    a = s.frame("!0F")
    check("!0F queue-full bit 5 set", a is not None and int(a.split(",")[1], 16) & 0x60 == 0x60, repr(a))
    a = s.frame("!0C100,20,0")
    check("!0C100,20,0 -> 1 queue full (13.8)", a == "1", repr(a))
    a = s.frame("!0N")
    check("!0N while RUN=1 -> 7", a == "7", repr(a))
    a = s.frame("!0H", 1_000_000_000) or s.wait_answer()
    check("!0H -> 8 after the stop (INTA=1)", a == "8", repr(a))
    a = s.frame("!0SR6")
    check("after H: ST6 INTA=1 RUN=1 INTCOM=1 (rest in queue)", a == "8,D0", repr(a))
    a = s.frame("!0V1000")
    check("!0V1000 -> 8 OK but interrupted (13.8)", a == "8", repr(a))
    a = s.frame("!0D")
    check("!0D deletes the queue -> 0, ST6=00", a == "0" and s.frame("!0SR6") == "0,00", repr(a))

    a = s.frame("!0SW8,F1")
    check("!0SW8,F1 -> 5 (13.8)", a == "5", repr(a))
    a = s.frame("!0SW2,2B")
    check("!0SW2,2B -> 0", a == "0", repr(a))
    a = s.frame("!0SR2")
    check("!0SR2 -> 0,2B (13.8)", a == "0,2B", repr(a))
    s.frame("!0SW2,00")

    # L0,0,0 end-of-queue marker (13.6.2)
    s.frame("!0V1000")
    s.frame("!0L2000,0,0")
    a = s.frame("!0L0,0,0")
    check("!0L0,0,0 while the queue runs -> 1", a == "1", repr(a))
    s.until(3_000_000_000 // 2); s.until(1_000_000_000)
    a = s.frame("!0L0,0,0")
    check("!0L0,0,0 once the queue is done -> 0", a == "0", repr(a))

    # 13.6.11 outputs, 13.7 spindle
    a = s.frame("!0O0,FB")
    check("!0O0,FB (coolant OUT1 on) -> outputs FB", a == "0" and s.state()["outputs"] == "FB", repr(a))
    a = s.frame("!0O0,FF")
    check("!0O0,FF all off -> outputs FF", a == "0" and s.state()["outputs"] == "FF", repr(a))
    a = s.frame("!7V300")
    st = s.state()
    check("!7V300 -> spindle 300, OUT0 on", a == "0" and st["spindle"] == 300 and int(st["outputs"], 16) & 1 == 0,
          repr((a, st["spindle"], st["outputs"])))
    a = s.frame("!7V0")
    st = s.state()
    check("!7V0 -> spindle 0, OUT0 off", a == "0" and st["spindle"] == 0 and st["outputs"] == "FF")
    a = s.frame("!7?")
    check("!7? answered at address 7", a is not None and a.startswith("0,IP114"), repr(a))

    # inputs
    s.cmd("in 1 FE")
    a = s.frame("!0I1")
    check("!0I1 -> 0,FE after in 1 FE", a == "0,FE", repr(a))
    s.cmd("in 1 FF")

    # KEEP / RESTORE worked example (13.6.9)
    s.frame("!0V1000")
    s.frame("!0L100000,0,0")
    s.until(500_000_000)
    a = s.frame("!0H") or s.wait_answer()
    check("KEEP ex.: !0H -> 8", a == "8", repr(a))
    a = s.frame("!0P")
    check("KEEP ex.: !0P -> x,y", a is not None and a.startswith("8,") and len(a.split(",")) == 3, repr(a))
    check("KEEP ex.: !0SR4", s.frame("!0SR4") == "8,00")
    check("KEEP ex.: !0SR5", s.frame("!0SR5") == "8,00")
    a = s.frame("!0SR6")
    check("KEEP ex.: !0SR6 -> INTA,RUN set", a is not None and int(a.split(",")[1], 16) & 0xC0 == 0xC0, repr(a))
    check("KEEP ex.: !0SW0,1A", s.frame("!0SW0,1A") == "8")
    check("KEEP ex.: !0SW1,3F", s.frame("!0SW1,3F") == "8")
    a = s.frame("!0K")
    check("KEEP ex.: !0K -> 0 (ST6 cleared)", a == "0", repr(a))
    a = s.frame("!0C0,0,-1000")
    check("after K: C refused", a == "1", repr(a))
    a = s.frame("!0L0,0,-1000")
    check("KEEP ex.: !0L0,0,-1000 -> 0", a == "0", repr(a))
    check("tool up done", s.idle())
    a = s.frame("!0L0,0,1000")
    check("KEEP ex.: !0L0,0,1000 -> 0", a == "0", repr(a))
    check("tool down done", s.idle())
    a = s.frame("!0R")
    check("KEEP ex.: !0R -> 8 (ST6 restored)", a == "8", repr(a))
    check("KEEP ex.: !0V500", s.frame("!0V500") == "8")
    check("KEEP ex.: !0XA", s.frame("!0XA") == "8")
    check("KEEP ex.: !0SW0,A2", s.frame("!0SW0,A2") == "8")
    check("KEEP ex.: !0SW1,78", s.frame("!0SW1,78") == "8")
    a = s.frame("!0G")
    check("KEEP ex.: !0G -> 0, continues", a == "0", repr(a))
    a = s.frame("!0SR6")
    check("after G: RUN=1 INTA=0", a == "0,40", repr(a))
    a = s.frame("!0D")
    check("!0D while running -> 7", a == "7", repr(a))
    a = s.frame("!0H") or s.wait_answer()
    s.frame("!0D")

    # interrupt from an input
    s.frame("!0SW0,01"); s.frame("!0SW2,00")
    s.frame("!0L100000,0,0")
    s.until(100_000_000)
    s.cmd("in 1 FE")
    s.until(500_000_000)
    a = s.frame("!0SR4")
    check("input IN0 grounded, enabled -> ST4 bit0, INTA", a == "8,01", repr(a))
    s.cmd("in 1 FF")
    s.frame("!0D"); s.frame("!0SW0,00")

    # errors 2, 3, 4, 6, addressing, index, repeat
    a = s.frame("!0ZZ")
    check("unknown command -> 3", a == "3", repr(a))
    a = s.frame("!0L1,x,3")
    check("syntax error -> 4", a == "4", repr(a))
    a = s.frame("!0G")
    check("!0G with nothing to start -> 6", a == "6", repr(a))
    data = b"!0L1"
    rx, _ = s.cmd("tx %s %d" % (data.hex(), s.now + len(data) * round(1e10 / 115200) + 1_000_000_000))
    check("unfinished frame -> 2 (watch dog)", rx == b"2\r", repr(rx))
    a = s.frame("!3?", 50_000_000)
    check("frame for address 3 -> no answer", a is None, repr(a))
    a = s.frame("!0@")
    s.frame("!0V1000")
    b2 = s.frame("!0@")
    check("!0@ index counts commands modulo 256", a is not None and b2 is not None and
          int(b2.split(",")[1]) == (int(a.split(",")[1]) + 1) % 256, repr((a, b2)))
    s.frame("!0SR2")
    a = s.frame("!0>")
    check("!0> repeats the last answer", a == "0,00", repr(a))

    # remaining example frames of 13.6
    for f in ["!0T5", "!0A50", "!0V10000", "!0VL25000,25000,30000", "!0XM200", "!0XM100", "!0VK", "!0VN",
              "!0$512", "!0B50000", "!0Y-"]:
        a = s.frame(f)
        check("%s -> 0 (13.6 example)" % f, a == "0" or (f == "!0Y-" and a == "0,Y-"), repr(a))
    a = s.frame("!0L1000,1000,20")
    check("!0L1000,1000,20 -> 0 (13.6.2)", a == "0", repr(a))
    check("L1000,1000,20 runs", s.idle())
    a = s.frame("!0C1000,1000,20")
    check("!0C1000,1000,20 -> 0 (13.6.2)", a == "0", repr(a))
    check("C1000,1000,20 runs", s.idle())
    p0 = s.state()["physical"][1]
    s.cmd("switch Y %d" % (p0 - 1500))
    a = s.frame("!0WY-20000,1000,2000,500", 1_000_000_000) or s.wait_answer()
    st = s.state()
    check("!0WY-20000,1000,2000,500 -> 0 after the reference (13.6.7)", a == "0", repr(a))
    check("W zeroes Y, stops one step back from the switch", st["position"][1] == 0 and
          st["physical"][1] == p0 - 1499, repr((st["position"], st["physical"], p0)))
    s.cmd("switch Y none")
    a = s.frame("!0EW10,AB"); b = s.frame("!0ER10")
    check("!0EW10,AB then !0ER10 -> 0,AB (13.6.10)", a == "0" and b == "0,AB", repr((a, b)))
    a = s.frame("!0EFW20,1.5"); b = s.frame("!0EFR20")
    check("!0EFW20,1.5 then !0EFR20 -> 0,1.5", a == "0" and b == "0,1.5", repr((a, b)))
    a = s.frame("!0EUW48,1000"); b = s.frame("!0EUR48")
    check("!0EUW48,1000 then !0EUR48 -> 0,1000", a == "0" and b == "0,1000", repr((a, b)))
    s.frame("!0EW10,FF"); s.frame("!0EUW20,4294967295"); s.frame("!0EUW48,4294967295")

    # J reset
    s.frame("!0V2000"); s.frame("!0O0,FB"); s.frame("!0NX5"); s.frame("!0%+")
    a = s.frame("!0J,%s" % csum("!0J,"))
    check("!0J -> answered", a is not None and a.startswith("0"), repr(a))
    a = s.frame("!0?", 200_000_000)
    check("deaf during the restart", a is None, repr(a))
    s.until(1_000_000_000); s.until(1_000_000_000)
    reset_state_checks(s, "after J (13.5)")
    # power-on
    s.frame("!0V2000"); s.frame("!0O0,FB"); s.frame("!0NX5"); s.frame("!0%+")
    _, l = s.cmd("power-on")
    check("rig power-on -> ok", l == "ok")
    s.until(1_000_000_000); s.until(1_000_000_000); s.until(100_000_000)
    reset_state_checks(s, "after power-on (13.5)")
    s.close()
    n = len(RESULTS)
    bad = RESULTS.count(False)
    print("%d checks, %d passed, %d failed" % (n, n - bad, bad))
    sys.exit(0 if bad == 0 else 1)


if __name__ == "__main__":
    main()
