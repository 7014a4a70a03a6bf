"""A run's time account: every wait of a link is booked under one head, so the heads sum
to the wall time — in virtual time with nothing left over (only the bookings move the
clock), over a real line with the suite's work as the rest; the console's lines say it."""

from __future__ import annotations

import pytest

from conformance.link.account import SUITE, Spent, TimeAccount, account_lines, suite_share
from conformance.run.runner import run
from conformance.run.selection import select
from conformance.targets import parse_target
from tests.emulator.process import Emulator

#: the account sums to the wall time within this share
WITHIN = 0.02


def _booked(totals: dict[str, float]) -> float:
    return sum(totals[str(s)] for s in Spent if s is not Spent.WORK)


def test_in_virtual_time_the_bookings_sum_to_the_clock():
    """The whole GVE84 catalogue on the embedded emulator: the clock moves only through
    what the links book, so the heads other than the suite's work cover the clocks'
    time, none of it counted twice."""
    result = run([parse_target("emu:GVE84-100")], select(None))
    (totals,) = [s["time"] for s in result.sessions.values()]
    wall = totals["wall"]
    assert wall > 60                        # the catalogue's motion alone takes minutes
    assert abs(_booked(totals) - wall) <= WITHIN * wall, totals
    assert totals[str(Spent.LINE)] > 0 and totals[str(Spent.MOTION)] > 0


@pytest.mark.pty
def test_over_a_paced_line_the_heads_sum_to_the_wall_time():
    """A real line (the emulator on a pty at 38,400 Bd): line time at least the bytes the
    cases' wire logs show, and the heads, the suite's work the rest, sum to the wall
    time the runner measured."""
    emu = Emulator("--model", "GVE84-100", "--pty", "--baud", "38400")
    try:
        target = parse_target(f"serial:{emu.first}?baud=38400", profile="GVE84-100",
                              max_travel=2000)
        result = run([target], select(["4.response.*", "10.4.halt.*"]))
    finally:
        emu.stop()
    (totals,) = [s["time"] for s in result.sessions.values()]
    assert abs(sum(v for k, v in totals.items() if k != "wall") - totals["wall"]) \
        <= WITHIN * totals["wall"]
    assert abs(totals["wall"] - result.seconds) <= WITHIN * result.seconds, \
        (totals, result.seconds)
    assert _booked(totals) <= totals["wall"]
    wire = sum(len(line.split(" ", 2)[2].encode().decode("unicode_escape"))
               for r in result.results for line in r.wire_log if line[:1].isdigit())
    assert totals[str(Spent.LINE)] >= wire * 10 / 38400 * (1 - WITHIN)
    assert totals[str(Spent.MOTION)] > 0            # H answers when the ramp ends


def test_a_virtual_account_follows_each_link_clock():
    account = TimeAccount(clock=lambda: 0.0)
    clocks = [3.0, 5.0]
    account.follow(lambda: clocks[0])
    account.book(Spent.LINE, 1.0)
    account.book(Spent.MOTION, 2.0)
    account.follow(lambda: clocks[1])
    account.book(Spent.WAITS, 4.0)
    account.end()
    totals = account.totals()
    assert totals["wall"] == 8.0
    assert totals[str(Spent.WORK)] == 1.0
    assert suite_share(totals) == pytest.approx(5.0 / 8.0)


def test_the_console_lines_give_each_head_and_the_suites_share():
    totals = {str(Spent.LINE): 30.0, str(Spent.ANSWERS): 10.0, str(Spent.MOTION): 40.0,
              str(Spent.MANUAL): 5.0, str(Spent.HANDS): 0.0, str(Spent.WAITS): 10.0,
              str(Spent.WORK): 5.0, "wall": 100.0}
    first, share = account_lines(totals)
    assert first.startswith("time: 100.0 s = line 30.0 s (30 %), answers 10.0 s (10 %)")
    assert "hands" not in first                       # a head with nothing booked
    assert share.endswith("15 % of it")
    assert {str(s) for s in SUITE} == {"suite waits", "suite work"}
    assert account_lines({"wall": 0.0}) == []
