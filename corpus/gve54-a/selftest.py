#!/usr/bin/env python3
"""Runs the worked examples of the GVE54 instruction set (given/GVE54-manual.txt)
against `sim.py --cosim` through the co-simulation protocol and checks the
documented answers.  One line per example; exit status 0 when all pass."""

import json
import sys

from cosimclient import CosimClient

SEC = 1_000_000_000
results = []


def check(name, cond, detail=""):
    results.append(bool(cond))
    print("%-4s %s%s" % ("ok" if cond else "FAIL", name, ("  [" + detail + "]") if detail else ""))


def example(fn):
    def run():
        try:
            fn()
        except Exception as e:            # a broken example is a failure, not a crash
            check(fn.__name__, False, "exception: %r" % e)
    run.__name__ = fn.__name__
    return run


def settle(c, f, limit=60):
    """Wait until SR6 shows RUN=0."""
    for _ in range(limit):
        r = f("!0SR6")
        if r is not None and not (int(r.split(",")[1], 16) & 0x40):
            return True
        c.wait(SEC // 2)
    return False


@example
def answers_table():
    """ODPOVEDI: the example table (Prikaz / Odpoved / Pozn.)."""
    c = CosimClient()
    f = c.frame
    check("table: !0L1000,0,0 -> 0 (OK)", f("!0L1000,0,0") == "0")
    settle(c, f)
    # !0C100,20,0 -> 1: the vector was not taken (the queue is full)
    f("!0V40")
    f("!0L100,0,0")
    n = 0
    while f("!0C100,20,0") == "0":
        n += 1
        if n > 200:
            break
    c2 = f("!0C100,20,0")
    check("table: !0C100,20,0 -> 1 (queue full, repeat it)", c2 == "1" and n == 95,
          "answer %r after %d C vectors" % (c2, n))
    # !0V1000 -> 8: OK, but interrupted (INTA=1)
    h = f("!0H", 5 * SEC)
    check("table: !0V1000 -> 8 (OK, INTA=1)", f("!0V1000") == "8", "H answered %r" % h)
    check("table: !0SW8,F1 -> D (5 with INTA=1)", f("!0SW8,F1") == "D")
    f("!0D")
    check("table: !0SW8,F1 -> 5 (parameter out of range)", f("!0SW8,F1") == "5")
    c.close()
    # !1PF -> 0,-1000,2000,50 and !1SR2 -> 0,2B on a unit at address 1
    c = CosimClient("--address", "1")
    f = c.frame
    f("!1L-1000,2000,50")
    for _ in range(20):
        c.wait(SEC // 2)
    check("table: !1PF -> 0,-1000,2000,50", f("!1PF") == "0,-1000,2000,50", f("!1PF") or "")
    f("!1SW2,2B")
    check("table: !1SR2 -> 0,2B", f("!1SR2") == "0,2B")
    check("address: a frame for unit 0 gets no answer from unit 1", f("!0PF", SEC // 10) is None)
    c.close()


@example
def command_examples():
    """The 'napr.:' examples of L, C, T, V, A."""
    c = CosimClient()
    f = c.frame
    check("L: !0L1000,1000,20 -> 0", f("!0L1000,1000,20") == "0")
    check("C: !0C1000,1000,20 -> 0 (continues the L)", f("!0C1000,1000,20") == "0")
    settle(c, f)
    check("L+C: PF -> 0,2000,2000,40", f("!0PF") == "0,2000,2000,40", f("!0PF"))
    check("T: !0T5 -> 0", f("!0T5") == "0")
    check("V: !0V10000 -> 0", f("!0V10000") == "0")
    check("A: !0A50 -> 0", f("!0A50") == "0")
    check("L range: !0L65536,0,0 -> 5", f("!0L65536,0,0") == "5")
    check("T range: !0T25 -> 5, V range: !0V39 -> 5", f("!0T25") == "5" and f("!0V39") == "5")
    c.close()


@example
def end_of_queue_marker():
    """L0,0,0 at the end of a queue: 1 until the queue before it is done, then 0."""
    c = CosimClient()
    f = c.frame
    f("!0V2000")
    f("!0L2000,0,0")
    f("!0C2000,0,0")
    first = f("!0L0,0,0")
    polls = 0
    while f("!0L0,0,0") != "0" and polls < 100:
        polls += 1
        c.wait(SEC // 10)
    check("L0,0,0: 1 while the queue runs", first == "1")
    check("L0,0,0: 0 once the queue is done, the axes at the end",
          polls < 100 and f("!0PF") == "0,4000,0,0", "after %d polls, PF %s" % (polls, f("!0PF")))
    c.close()


@example
def keep_restore():
    """The K/R example: H, P, SR4..SR6, masks, K, lift, lower, R, V500, XA, masks, G."""
    c = CosimClient()
    f = c.frame
    f("!0V1000")
    f("!0L4000,2000,0")
    c.wait(SEC)
    h = f("!0H", 5 * SEC)
    check("KEEP ex.: !H answers once stopped, INTA=1 -> 8", h == "8", repr(h))
    p = f("!0P")
    x = int(p.split(",")[1])
    check("KEEP ex.: !P -> where it stopped", p.startswith("8,") and 0 < x < 4000, p)
    check("KEEP ex.: SR4, SR5 -> no user interrupt", f("!0SR4") == "8,00" and f("!0SR5") == "8,00")
    check("KEEP ex.: SR6 -> INTA, RUN (rest in queue), INTCOM", f("!0SR6") == "8,D0", f("!0SR6"))
    check("KEEP ex.: SW0,1A / SW1,3F", f("!0SW0,1A") == "8" and f("!0SW1,3F") == "8")
    check("KEEP ex.: K -> queue and ST4..6 kept, cleared", f("!0K") == "0" and f("!0SR6") == "0,00")
    check("KEEP ex.: L0,0,-1000 lifts the tool", f("!0L0,0,-1000") == "0")
    settle(c, f)
    check("KEEP ex.: L0,0,1000 lowers it", f("!0L0,0,1000") == "0")
    settle(c, f)
    check("KEEP ex.: R -> queue and ST6 back (INTA=1 RUN=1)", f("!0R") == "8" and f("!0SR6") == "8,D0")
    check("KEEP ex.: V500 and XA", f("!0V500") == "8" and f("!0XA") == "8")
    check("KEEP ex.: SW0,A2 / SW1,78", f("!0SW0,A2") == "8" and f("!0SW1,78") == "8")
    check("KEEP ex.: G -> 0, INTA cleared, RUN", f("!0G") == "0" and f("!0SR6") == "0,40")
    settle(c, f)
    check("KEEP ex.: the rest of the vector done", f("!0PF") == "0,4000,2000,0", f("!0PF"))
    c.close()


@example
def microsteps():
    """M4 L100,100,100 PF -> 0,400,400,400; the rounding example with L-1,0,1."""
    c = CosimClient()
    f = c.frame
    check("M: !0M4 -> 0", f("!0M4") == "0")
    f("!0L100,100,100")
    settle(c, f)
    check("M4 L100,100,100: PF -> 0,400,400,400", f("!0PF") == "0,400,400,400", f("!0PF"))
    f("!0MF")
    f("!0N")
    f("!0L1001,500,399")
    settle(c, f)
    check("rounding ex.: PF -> 0,1001,500,399", f("!0PF") == "0,1001,500,399", f("!0PF"))
    check("rounding ex.: L-1,0,1 (in 1/16)", f("!0L-1,0,1") == "0")
    settle(c, f)
    check("rounding ex.: PF -> 0,1000,500,400", f("!0PF") == "0,1000,500,400", f("!0PF"))
    check("rounding ex.: M4 -> 0", f("!0M4") == "0")
    f("!0L10000,0,0")
    c.wait(SEC // 10)
    check("M while moving -> 7", f("!0MF") == "7")
    c.close()


@example
def halt_and_go():
    """H answers only after braking; G with nothing stopped; D; N while running."""
    c = CosimClient()
    f = c.frame
    f("!0V5000")
    f("!0L20000,0,0")
    c.wait(SEC // 2)
    t0 = c.now
    check("N while RUN=1 -> 7", f("!0N") == "7")
    check("D while running -> 7", f("!0D") == "7")
    t0 = c.now
    h = f("!0H", 5 * SEC)
    check("H: answered after braking (8)", h == "8" and c.now - t0 > 50_000_000,
          "%r after %.1f ms" % (h, (c.now - t0) / 1e6))
    check("D: deletes the queue, ST6=00", f("!0D") == "0" and f("!0SR6") == "0,00")
    check("G without INTA -> 6", f("!0G") == "6")
    c.close()


@example
def interrupts():
    """An enabled input stops the motion with a ramp, sets INTA and its ST4 bit."""
    c = CosimClient()
    f = c.frame
    f("!0SW0,80")                        # INTR7 (I1 bit 7, STOP button) enabled, active at 0
    f("!0V5000")
    f("!0L20000,0,0")
    c.wait(SEC // 2)
    assert c.cmd("in 1 7F") == ["ok"]
    s = f("!0SR6")
    check("INTR7: SR6 -> INTA, RUN, STOP (ramp)", s == "8,C1", s)
    c.wait(SEC)
    check("INTR7: SR4 -> 80, I1 -> 7F", f("!0SR4") == "8,80" and f("!0I1") == "8,7F")
    check("INTR7: stopped with the rest in the queue (8,C0)", f("!0SR6") == "8,C0")
    c.cmd("in 1 FF")
    check("G resumes: 0, SR4 cleared", f("!0G") == "0" and f("!0SR4") == "0,00")
    settle(c, f)
    check("the vector completed", f("!0PF") == "0,20000,0,0")
    c.close()


@example
def misc_commands():
    """Reset state, EEPROM, outputs, index, repeat, version, Q, F, J."""
    c = CosimClient()
    f = c.frame
    st = json.loads(c.cmd("state")[0])
    check("reset: ST0..ST6 = 00, O0,FF", st["status"] == ["00"] * 7 and st["outputs"] == "FF")
    check("ER/EW: EW10,5A then ER10 -> 0,5A", f("!0EW10,5A") == "0" and f("!0ER10") == "0,5A")
    check("O0,FE -> 0, output 0 on", f("!0O0,FE") == "0" and json.loads(c.cmd("state")[0])["outputs"] == "FE")
    q = f("!0Q")
    check("Q: ddmmrrpp", q is not None and q.startswith("0,") and len(q) == 10 and q[2:].isdigit(), q)
    check("?: version", (f("!0?") or "").startswith("0,IP54"))
    check("F: same as SR6 + queue bit", f("!0F") == "0,00")
    check("@: index of the last command", f("!0@") == "0,06" and f("!0@") == "0,06")
    pf = f("!0PF")
    check(">: repeats the last answer", f("!0>") == pf)
    check("unknown command -> 3, syntax -> 4", f("!0Z") == "3" and f("!0L1,2") == "4")
    check("J: answered, then deaf ~2 s, then reset", f("!0J") == "0" and f("!0@", SEC // 2) is None)
    c.wait(2 * SEC)
    check("J: index and outputs reset", f("!0@") == "0,00" and json.loads(c.cmd("state")[0])["outputs"] == "FF")
    c.close()


def main():
    for ex in (answers_table, command_examples, end_of_queue_marker, keep_restore,
               microsteps, halt_and_go, interrupts, misc_commands):
        ex()
    bad = results.count(False)
    print("%d checks, %d failed" % (len(results), bad))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
