"""A small run built by hand, with what the reports must show: every verdict, hostile
unit bytes, a long passing wire log, many checks and a motion trace."""

from __future__ import annotations

from conformance.run.metadata import RunMeta
from conformance.run.runner import CaseResult, RunResult
from conformance.verdicts.verdict import COULD_NOT_TEST, FAIL, INFO, NON_STRICT, PASS

#: what a hostile or broken unit may send back: NUL, controls, markup, CDATA's end
HOSTILE = "\x00\x07\x1b[31m</pre><script>alert(1)</script> & \"q\" ]]> \x7f\ud800"

TRACE = {"name": "trapezoid X", "axes": ["X", "Y", "Z"],
         "samples": [(t / 100, [t * t, 0, 0]) for t in range(101)],
         "model": [(t / 10, [100.0 * t * t, 0, 0]) for t in range(11)],
         "tolerance": {"seconds": 0.002, "steps": 1}, "params": {"V": 1000, "A": 20}}


def result(id: str, verdict: str, **kw) -> CaseResult:
    section = id.rsplit(".", 2)[0]
    kw.setdefault("checks", [{"ok": verdict == PASS, "what": "a check", "observed": "0",
                              "expected": "0", "tag": "M", "rule": "a rule"}])
    return CaseResult(id, section, "a rule", "M", "spec", "GVE84-100", "emu:GVE84-100",
                      verdict, **kw)


def toy_run(**meta) -> RunResult:
    results = [
        result("10.5.toy.passes", PASS, wire_log=[f"0.{i:09d} > !0@\\r" for i in range(100)],
               checks=[{"ok": True, "what": f"vector {i}", "observed": "0", "expected": "0",
                        "tag": "M", "rule": "r"} for i in range(50)]),
        result("10.2.toy.moves", PASS, traces=[TRACE]),
        result("6.toy.fails", FAIL, wire_log=["# link", f"< {HOSTILE}"],
               checks=[{"ok": False, "what": HOSTILE, "observed": HOSTILE, "expected": "0",
                        "tag": "M", "rule": "r"}]),
        result("8.toy.lenient", NON_STRICT,
               checks=[{"ok": False, "what": "> repeats the last frame", "observed": "5",
                        "expected": "0", "tag": "D", "rule": "8.repeat.answer"}]),
        result("9.toy.informs", INFO,
               checks=[{"ok": False, "what": "ST6 free bits", "observed": "80",
                        "expected": "00", "tag": "D-info", "rule": "10.3.st6.free"}]),
        result("10.3.toy.needs-a-hand", COULD_NOT_TEST, checks=[],
               notes=["nobody grounded IN0 (X limit)"]),
    ]
    m = RunMeta(started="2026-11-25T10:00:00+01:00", finished="2026-11-25T10:01:00+01:00",
                operator="J. Novák", settings="dev", seed=1234, mutant=None,
                max_travel=2000, cases=["10.*"], **meta)
    t = m.target("emu:GVE84-100")
    t.kind, t.profile, t.version, t.processor_id = "emu", "GVE84-100", "IP84 v3 27.1.2010", \
        "25020304"
    return RunResult("toy-run", results, ["emu:GVE84-100"], settings="dev", meta=m)
