"""A correct unit behind a line that now and then holds an answer longer than the
timeout the round trip measured at the start allows (a USB adapter's host under load)
gets no FAIL: the late answer is its frame's and noted; a unit that answers twice still
FAILs."""

from __future__ import annotations

import pytest

from conformance.run.runner import run
from conformance.run.selection import select
from conformance.targets import parse_target
from conformance.verdicts.verdict import FAIL, PASS
from tests.conformance.safety.proxy import HOSTILE, unit_behind_proxy
from tests.emulator.process import Emulator
from tests.usb_relay import UsbRelay

pytestmark = pytest.mark.pty


def test_answers_held_past_their_timeout_are_taken_late_not_failed() -> None:
    emu = Emulator("--model", "GVE84-100", "--pty")
    # after the session's start (its EEPROM backup: about 275 answers), every 5th answer
    # held 1 s, 4 times: past the ~0.3 s a 16 ms line's timeout gives, and past it still
    # where a loaded machine made the round trip measured at the start slower (0.6 s was
    # not, once), within the second of grace a late answer has after it
    relay = UsbRelay(emu.first, latency_ms=16, jitter_ms=3, stall_every=5, stall_ms=1000,
                     stall_from=275, stalls=4)
    try:
        target = parse_target(f"serial:{relay.path}?baud=115200", profile="GVE84-100",
                              allow_destructive=True, max_travel=1000)
        results = run([target], select(["10.6.eeprom.round-trip"])).results
    finally:
        relay.close()
        emu.stop()
    assert relay.stalls == 0
    late = [n for r in results for n in r.notes if n.startswith("late answer")]
    assert late, [r.notes for r in results]
    assert {r.verdict for r in results} == {PASS}, \
        [(r.id, [c["what"] for c in r.checks if not c["ok"]]) for r in results]


def test_a_unit_that_answers_twice_still_fails_behind_the_relay() -> None:
    with unit_behind_proxy("--model", "GVE84-100", transform=HOSTILE["twice"]) as (_, proxy):
        relay = UsbRelay(proxy.path, latency_ms=16, jitter_ms=3)
        try:
            target = parse_target(f"serial:{relay.path}?baud=115200", profile="GVE84-100",
                                  max_travel=1000)
            results = run([target], select(["8.index.counts-every-frame"])).results
        finally:
            relay.close()
    assert [r.verdict for r in results] == [FAIL]
    assert any("answered twice" in c["what"] for c in results[0].checks if not c["ok"])
