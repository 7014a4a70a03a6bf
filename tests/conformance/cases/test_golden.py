"""The golden exchanges are the manuals' data and replay as they are: on a real unit an
exchange that leaves the envelope ends COULD-NOT-TEST saying which envelope it needs, and
with that envelope it runs."""

from __future__ import annotations

import pytest

from conformance.catalogue import select
from conformance.runner import run_case
from conformance.verdict import COULD_NOT_TEST, PASS
from tests.conformance.cases.used import used_unit


@pytest.mark.parametrize(("case_id", "profile", "ran"), [
    ("11.golden.g6-keep-restore", "GVE84-100", 0),     # H, K, R: the kept queue counted whole
    ("11.golden.g3-packet", "GVE84-100", 0),           # a packet judged whole before *E
    # a 1000-step vector at V10 at the head, then vectors until the refused one: none ends
    # while the queue fills, so the envelope the note names is enough
    ("11.golden.g4c-buffer-full", "GVE114-500", 0),
])
def test_a_golden_exchange_says_the_envelope_it_needs_and_runs_in_it(case_id, profile, ran):
    (c,) = select([case_id])
    stopped = run_case(c, used_unit(profile, max_travel=1000))
    assert stopped.verdict == COULD_NOT_TEST
    need = int(stopped.notes[0].split("--max-travel ", 1)[1].split()[0])
    assert need > 1000
    short = run_case(c, used_unit(profile, max_travel=need - 1))
    assert short.verdict == COULD_NOT_TEST and f"--max-travel {need} or more" in short.notes[0]
    assert run_case(c, used_unit(profile, max_travel=need + ran)).verdict == PASS


def test_an_exchange_no_envelope_lets_through_says_so():
    # on the GVE114 a member's trailing ,XX may be the A axis: a vector the guard cannot bound
    (c,) = select(["11.golden.g3-packet"])
    stopped = run_case(c, used_unit("GVE114-500", max_travel=100_000))
    assert stopped.verdict == COULD_NOT_TEST and "the emulator only" in stopped.notes[0]


def test_a_d_record_takes_the_extra_lines_of_a_unit_reading_it_otherwise():
    # a unit that remembers @ answers > after @ with two lines where g7 expects one (a
    # [D] record): the second line is that record's, not a second answer nor SR0's
    from conformance.targets import parse_target
    from conformance.verdict import NON_STRICT
    (c,) = select(["11.golden.g7-reset-state"])
    r = run_case(c, parse_target("emu:GVE84-100?reading=index-remembered"))
    assert r.verdict == NON_STRICT, r.notes
    (failed,) = [ch for ch in r.checks if not ch["ok"]]
    assert failed["observed"] == "!0@\\r0,0\\r" and failed["tag"] == "D"
