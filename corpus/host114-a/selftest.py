#!/usr/bin/env python3
"""Self-test for host.py against fakeunit.py on a pseudo-terminal.

python3 selftest.py   -> exit 0 when everything passes.
"""

import os
import subprocess
import sys
import tempfile
import threading
import time
import tty

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import host  # noqa: E402
from fakeunit import FakeUnit  # noqa: E402

FAILS = []


def check(cond, what):
    print(("  ok   " if cond else "  FAIL ") + what)
    if not cond:
        FAILS.append(what)


# ---------------------------------------------------------------------------
# 1. framing and checksums against the manual's worked examples
# ---------------------------------------------------------------------------

def test_frames():
    print("framing / checksums (13.3.2, 13.4, 13.8)")
    f = host.frame
    check(f(0, "A100", True) == b"!0A100,4F\r", "!0A100 -> !0A100,4F")
    check(f(0, "%-", True) == b"!0%-,CF\r", "!0%- -> !0%-,CF")
    check(f(0, "%+", False) == b"!0%+\r", "!0%+ sent plain")
    check(f(0, "L1000,1000,20", False) == b"!0L1000,1000,20\r", "plain frame !0L1000,1000,20")
    manual_packet = [
        "!0*S,FA", "!0C697,30,0,51", "!0C692,92,0,54", "!0C682,151,0,7F",
        "!0C665,209,0,84", "!0C645,268,0,87", "!0C619,322,0,7F", "!0C589,375,0,8D",
        "!0C553,425,0,80", "!0C515,471,0,7F", "!0C471,515,0,7F", "!0*E10,4D",
    ]
    vecs = [(697, 30, 0), (692, 92, 0), (682, 151, 0), (665, 209, 0), (645, 268, 0),
            (619, 322, 0), (589, 375, 0), (553, 425, 0), (515, 471, 0), (471, 515, 0)]
    ours = [f(0, "*S", True)]
    ours += [f(0, host.vec_text("C", (x, y, z, 0)), True) for x, y, z in vecs]
    ours.append(f(0, "*E%d" % len(vecs), True))
    check(ours == [(m + "\r").encode() for m in manual_packet],
          "manual packet example (13.4) reproduced byte for byte")
    r = host.parse_answer("0,10,E9", True)
    check(r is not None and r.err == 0 and r.fields == ["10"], "answer 0,10,E9 valid")
    r = host.parse_answer("0,5C", True)
    check(r is not None and r.err == 0 and r.fields == [], "answer to %+ '0,5C' valid")
    check(host.parse_answer("0,10,E8", True) is None, "damaged checksum rejected")
    r = host.parse_answer("8", False)
    check(r is not None and r.err == 0 and r.inta, "answer 8 = OK with INTA (13.8)")
    r = host.parse_answer("0,-1000,2000,50", False)
    check(r is not None and host.SHAPES["xyz"](r.fields), "PF answer 0,-1000,2000,50")
    r = host.parse_answer("0,2B", False)
    check(r is not None and host.SHAPES["hex"](r.fields), "SR2 answer 0,2B")


# ---------------------------------------------------------------------------
# 2. jobs against the fake unit
# ---------------------------------------------------------------------------

JOB = """# self-test job
speed 20000
100,0,0
100,10,0
100,20,0
0,100,0        # 90 degree corner
-100,100,0
-200,0,0,50
0,0,0          # zero vector
0,0,0,300      # A only
speed 15000
0,-150,20
50,-50,-20
-40,-30,0
"""


def big_job(n):
    lines = ["speed 30000"]
    for i in range(n):
        k = i % 8
        lines.append("%d,%d,%d" % ((120, 100, 0, -100, -120, -100, 0, 100)[k],
                                   (0, 80, 120, 80, 0, -80, -120, -80)[k], (i % 3) - 1))
    return "\n".join(lines) + "\n"


def expected(job_text):
    return [tuple(v[:4]) for v in host.parse_job_text(job_text)]


def run_case(name, job_text, args, fake_kw=None, during=None, expect_rc=0,
             check_exec=True, timeout=90):
    print(name)
    master, slave = os.openpty()
    tty.setraw(slave)
    path = os.ttyname(slave)
    fake = FakeUnit(master, **(fake_kw or {})).start()
    with tempfile.NamedTemporaryFile("w", suffix=".job", delete=False) as jf:
        jf.write(job_text)
        jobpath = jf.name
    cmd = [sys.executable, os.path.join(HERE, "host.py"), path, jobpath,
           "--timeout", "0.3"] + args
    t0 = time.monotonic()
    proc = subprocess.Popen(cmd, stderr=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    if during:
        threading.Thread(target=during, args=(fake,), daemon=True).start()
    try:
        out, err = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        proc.kill()
        out, err = proc.communicate()
        err += "\n<killed: host hung>"
    dt = time.monotonic() - t0
    fake.stop = True
    time.sleep(0.1)
    os.close(master)
    os.close(slave)
    os.unlink(jobpath)
    ok_rc = proc.returncode == expect_rc
    check(ok_rc, "exit code %s (expected %s) in %.1f s" % (proc.returncode, expect_rc, dt))
    if check_exec:
        got = [tuple(e[1:5]) for e in fake.executed]
        exp = expected(job_text)
        same = got == exp
        check(same, "unit executed all %d vectors exactly once, in order" % len(exp))
        if not same:
            print("    executed %d, expected %d" % (len(got), len(exp)))
            for i, (a, b) in enumerate(zip(got, exp)):
                if a != b:
                    print("    first difference at %d: got %s expected %s" % (i, a, b))
                    break
    if not ok_rc or (check_exec and FAILS and FAILS[-1].startswith("unit executed")):
        print("    --- host stderr ---")
        print("    " + "\n    ".join(err.strip().splitlines()[-25:]))
    else:
        last = err.strip().splitlines()[-1] if err.strip() else ""
        print("    host: %s" % last)
    return fake, err


def faulty(pattern):
    """pattern: dict modulus -> action, applied to reply numbers after setup."""
    def fault(kind, n, cmd):
        if n < 25:
            return None
        for (mod, rem), act in pattern.items():
            if n % mod == rem:
                return act
        return None
    return fault


def main():
    test_frames()

    run_case("short job, plain, single vectors", JOB, [])
    run_case("short job, checksums + packets", JOB, ["--checksums", "--packets"])
    run_case("longer job, packets, @ not counting itself, errors not counted",
             big_job(150), ["--packets"],
             {"at_counts_itself": False, "errors_counted": False})
    run_case("small unit queue (capacity 4): queue-full answers (error 1)",
             big_job(60), [], {"capacity": 4})
    run_case("noisy line, checksums: lost / damaged / late / noisy answers",
             big_job(60), ["--checksums"],
             {"fault": faulty({(7, 3): "drop", (11, 5): "corrupt", (13, 0): "noise",
                               (29, 8): ("delay", 0.45)}), "capacity": 16})
    run_case("noisy line, plain: lost / garbled answers",
             big_job(50), [],
             {"fault": faulty({(9, 4): "drop", (10, 7): "corrupt", (23, 2): ("delay", 0.45)})})
    run_case("noisy line, plain, @ not counting itself (position recovery)",
             big_job(30), [],
             {"fault": faulty({(7, 3): "drop", (11, 5): "corrupt", (29, 8): ("delay", 0.45)}),
              "capacity": 8, "at_counts_itself": False})
    run_case("noisy line, checksums, unit whose '>' re-executes (must not be trusted)",
             big_job(30), ["--checksums"],
             {"fault": faulty({(7, 3): "drop", (11, 5): "corrupt"}), "capacity": 8,
              "repeat_reexecutes": True})
    run_case("noisy line, checksums + packets",
             big_job(150), ["--checksums", "--packets"],
             {"fault": faulty({(5, 2): "drop", (7, 1): "corrupt", (17, 3): ("delay", 0.45)})})

    def restart_mid(fake):
        while len(fake.executed) < 20:
            time.sleep(0.005)
        fake.restart(silent=0.8)
    run_case("power loss mid-job, checksums -> give up (exit 4)", big_job(200),
             ["--checksums", "--speed", "3000"], {}, during=restart_mid,
             expect_rc=host.EXIT_STATE, check_exec=False)
    run_case("power loss mid-job, plain, all queued -> give up (exit 4)", big_job(200),
             [], {}, during=restart_mid, expect_rc=host.EXIT_STATE, check_exec=False)
    run_case("power loss while feeding (queue 8), plain -> give up (exit 4)", big_job(200),
             [], {"capacity": 8}, during=restart_mid, expect_rc=host.EXIT_STATE,
             check_exec=False)
    run_case("power loss while feeding (queue 8), checksums+packets -> give up (exit 4)",
             big_job(200), ["--checksums", "--packets"], {"capacity": 8}, during=restart_mid,
             expect_rc=host.EXIT_STATE, check_exec=False)

    def stuck(fake):
        while len(fake.executed) < 5:
            time.sleep(0.005)
        fake.stuck = True
    run_case("motion never finishes -> bounded wait, exit 6", big_job(30),
             ["--time-margin", "2"], {"capacity": 8}, during=stuck,
             expect_rc=host.EXIT_TIMEOUT, check_exec=False)

    def stop_mid(fake):
        while len(fake.executed) < 15:
            time.sleep(0.005)
        fake.input_interrupt(7)
    fake, _ = run_case("STOP input mid-job -> exit 3, queue left in unit", big_job(200), [],
                       {"capacity": 8}, during=stop_mid, expect_rc=host.EXIT_INTR, check_exec=False)
    got = [tuple(e[1:5]) for e in fake.executed]
    check(got == expected(big_job(200))[:len(got)], "executed part is an exact prefix")

    def stop_and_start(fake):
        while len(fake.executed) < 15:
            time.sleep(0.005)
        fake.input_interrupt(7)
        time.sleep(1.0)
        fake.in1 = 0xBF            # START (IN6) pressed -> host sends G
        time.sleep(0.5)
        fake.in1 = 0xFF
    run_case("STOP then START with --interrupt-wait: resumes, completes",
             big_job(100), ["--interrupt-wait", "10"], {"capacity": 8}, during=stop_and_start)

    def dead(fake):
        fake.silent_until = time.monotonic() + 3600
    run_case("no unit answering -> exit 2", JOB, ["--retries", "2"], {}, during=dead,
             expect_rc=host.EXIT_COMM, check_exec=False)

    print()
    if FAILS:
        print("SELFTEST FAILED: %d check(s)" % len(FAILS))
        for f in FAILS:
            print("  - " + f)
        return 1
    print("SELFTEST PASSED")
    return 0


if __name__ == "__main__":
    sys.exit(main())
