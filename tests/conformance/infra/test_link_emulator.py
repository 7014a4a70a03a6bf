"""The link on the embedded emulator: faults in both directions, virtual time (spec 2-5)."""

from __future__ import annotations

import time

import pytest

from conformance.targets import parse_target


@pytest.fixture
def link():
    return parse_target("emu:GVE84-100").open_link()


def test_a_dropped_frame_gets_no_answer_and_the_line_goes_on(link):
    link.inject("host", "drop")
    assert link.send("SR0") is None
    assert link.send("SR0").code == 0


def test_a_lower_cased_letter_is_an_unknown_command(link):
    link.inject("host", "corrupt", at=2, xor=0x20)        # !0SR0 -> !0sR0 (spec 3)
    assert link.send("SR0").code == 3


def test_a_stall_past_the_watchdog_is_error_2_in_virtual_time(link):
    started = time.perf_counter()
    link.inject("host", "delay", at=3, seconds=0.5)       # 100 ms watchdog (spec 3)
    assert link.send("SR0").code == 2
    assert link.now >= 100_000_000 and time.perf_counter() - started < 0.4


def test_a_split_frame_within_the_watchdog_is_answered(link):
    link.inject("host", "split", size=2, seconds=0.01)
    assert link.send("SR0").code == 0


def test_a_truncated_response_is_not_well_formed(link):
    link.inject("unit", "truncate", keep=1)
    r = link.send("SR0")
    assert r is not None and not r.well_formed
    assert any("fault unit truncate" in line for line in link.transcript_lines())
