"""The golden exchanges are the manuals' data and replay as they are: on a real unit an
exchange that leaves the envelope ends COULD-NOT-TEST saying which envelope it needs, and
with that envelope it runs."""

from __future__ import annotations

import pytest

from conformance.cases.s11_golden import envelope_needed
from conformance.run.runner import run, run_case
from conformance.run.selection import select
from conformance.targets import parse_target
from conformance.verdicts.verdict import COULD_NOT_TEST, PASS
from gve_fixtures import golden_transcripts
from gve_fixtures.profile import available_profiles, load_profile
from gve_fixtures.transcript import load
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


@pytest.mark.parametrize("profile", [p for p in available_profiles()
                                     if load_profile(p).family in ("GVE84", "GVE114")])
def test_the_packet_runs_in_checksum_mode_on_every_profile(profile):
    # each member's last field is its checksum, read as the unit reads it: not the
    # GVE114's A component (which would be 51, 54, then 7F: no envelope bounds that)
    (c,) = select(["11.golden.g3-packet"])
    t = next(t for t in map(load, golden_transcripts()) if t.meta["title"].startswith("A packet"))
    need = envelope_needed(t, load_profile(profile))
    assert need is not None and need < 10_000
    r = run_case(c, used_unit(profile, max_travel=need))
    assert r.verdict == PASS, (r.notes, r.failed_checks)


def test_a_d_record_takes_the_extra_lines_of_a_unit_reading_it_otherwise():
    # a unit that remembers @ answers > after @ with two lines where g7 expects one (a
    # [D] record): the second line is that record's, not a second answer nor SR0's
    from conformance.targets import parse_target
    from conformance.verdicts.verdict import NON_STRICT
    (c,) = select(["11.golden.g7-reset-state"])
    r = run_case(c, parse_target("emu:GVE84-100?reading=index-remembered"))
    assert r.verdict == NON_STRICT, r.notes
    (failed,) = [ch for ch in r.checks if not ch["ok"]]
    assert failed["observed"] == "!0@\\r0,0\\r" and failed["tag"] == "D"


@pytest.mark.parametrize("reading", ["go-clears-then-nothing", "go-nothing-queued"])
def test_the_interrupted_golden_s_clean_up_takes_either_answer_to_g_with_nothing_queued(
        reading):
    # G4d's G only cleans up: 0, or 6 with nothing to start (spec 5 allows both)
    result = run([parse_target(f"emu:GVE84-100?reading={reading}")],
                 select(["11.golden.g4d-interrupted"]))
    assert [r.verdict for r in result.results] == [PASS]
