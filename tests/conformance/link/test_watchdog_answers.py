"""An answer a watchdog can explain is the watchdog's (conformance/link/link.py): after a
lone `!`, a frame without its CR or an open packet, a unit with a watchdog of its own
time (half a second, a second) answers 2 when the suite lets them go; that answer is
judged by the watchdog's rule, never taken for a second answer to the frame before. A
second answer to a complete frame, with nothing left for a watchdog, still FAILs."""

from __future__ import annotations

import pytest

from conformance.case.context import REGISTRY
from conformance.link.strays import OPEN_FRAME, TWICE, WATCHDOG_RULES
from conformance.run.runner import run_case
from conformance.run.selection import select
from conformance.targets import parse_target
from conformance.verdicts.verdict import ERROR, FAIL, NON_STRICT
from tests.conformance.link.test_link import _Line, real_link

WATCHDOGS = ["lone-bang-answered,half-second-watchdog,packet-watchdog",
             "lone-bang-answered,slow-watchdog,packet-watchdog"]


def _link(readings: str):
    return parse_target(f"emu:GVE84-100?reading={readings}").session.open_link()


@pytest.mark.parametrize("readings", WATCHDOGS)
def test_a_unit_s_own_watchdog_time_fails_no_case_of_frames_and_packets(readings: str):
    target = parse_target(f"emu:GVE84-100?reading={readings}")
    bad = {}
    for c in select(["3.frame.*", "3.params.*", "7.packet.*", "7.machine.*"]):
        r = run_case(c, target, "mutation")
        if r.verdict in (FAIL, ERROR):
            bad[c.id] = [ch["what"] for ch in r.checks if not ch["ok"]]
    assert bad == {}


@pytest.mark.parametrize(("case_id", "rule"), [
    ("3.frame.lone-bang-silent", "3.frame.watchdog-lone-bang"),
    ("7.packet.bad-checksum-member.corrupted-end", "7.packet.open-until-end")])
def test_the_watchdog_s_answer_is_graded_by_its_rule(case_id: str, rule: str):
    target = parse_target(f"emu:GVE84-100?reading={WATCHDOGS[1]}")
    r = run_case(REGISTRY[case_id], target, "mutation")
    failed = [c for c in r.checks if not c["ok"]]
    assert r.verdict == NON_STRICT and rule in {c["rule"] for c in failed}
    assert all(c["tag"] != "always" for c in failed)


def test_a_lone_bang_answered_after_the_case_s_wait_is_the_watchdog_s():
    ln = _link("lone-bang-answered,slow-watchdog")
    assert ln.send("V1000").raw == b"0\r"
    ln.send_raw(b"!")
    assert ln.wait(0.5) == b""                    # a second's watchdog: not yet
    ln.settle(final=True)                         # the longest watchdog waited out
    assert [(v.rule, v.always) for v in ln.violations] == [
        ("3.frame.watchdog-lone-bang", False)]


def test_a_frame_left_without_its_cr_answered_2_is_what_our_reading_does_too():
    ln = _link("half-second-watchdog")
    ln.send_raw(b"!0V1000")
    assert ln.left_open() == OPEN_FRAME and WATCHDOG_RULES[OPEN_FRAME] == "3.frame.watchdog"
    ln.settle(final=True)
    assert ln.violations == [] and ln.log[-1].data == b"2\r"


def test_a_packet_the_next_frame_goes_on_with_is_not_waited_for():
    ln = _link("packet-watchdog")
    ln.send("*S", answer=False)
    ln.send("C10,0,0", answer=False)
    assert ln.send("*E1").raw == b"0,1\r" and ln.violations == []


def test_a_second_answer_to_a_complete_frame_still_fails():
    port = _Line([b"0\r"], then=b"2\r")           # V1000 answered, then a 2 no one asked
    ln = real_link(port)
    assert ln.send("V1000").raw == b"0\r"
    ln.settle()
    assert [(v.rule, v.always) for v in ln.violations] == [(TWICE, True)]
    assert "answered twice" in ln.violations[0].text


def test_a_watchdog_s_answer_read_while_it_arrives_is_read_whole():
    # the packet's watchdog writes `2,1` at 0.5 s; a wait that ends while its bytes are
    # on their way takes the rest of the line too: never its tail as the next answer
    for us in range(0, 1200, 20):
        ln = _link("packet-watchdog")
        ln.send("*S", answer=False)
        ln.send("C10,0,0", answer=False)
        got = ln.wait(0.5 + us / 1e6)
        assert got in (b"", b"2,1\r"), us
        if got:
            r = ln.send("SR6")
            assert r is not None and r.raw == b"0,00\r" and ln.violations == [], (us, r)


def test_an_answer_that_began_before_its_timeout_is_read_to_its_end():
    port = _Line([b"2", b",1,BB\r"])            # the timeout ran out after its first byte
    ln = real_link(port)
    r = ln.send("*E1", timeout=0.1)
    assert r is not None and r.raw == b"2,1,BB\r" and ln.violations == [] and ln.late == []


def test_an_answer_that_began_in_time_is_not_noted_late():
    port = _Line([b"0,1", b"2\r"])               # the timeout ran out after three bytes
    ln = real_link(port)
    r = ln.send("SR6")
    assert r is not None and r.raw == b"0,12\r" and ln.late == [] and ln.violations == []
