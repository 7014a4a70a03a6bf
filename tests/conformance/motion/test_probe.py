"""How the motion probe reads the frames of its script (spec 10)."""

from __future__ import annotations

import pytest

from conformance.link.account import Spent
from conformance.motion.probe import SETTLE, _split, _stated_instead, _when_done
from conformance.protocol.wire import parse_response
from conformance.run.runner import run
from conformance.run.selection import select
from conformance.targets import parse_target
from gve_fixtures.profile import load_profile
from tests.conformance.cases.used import used_unit


@pytest.mark.parametrize(("body", "read"), [
    ("L600,0,0", ("L", "600,0,0")), ("C-700,0,0", ("C", "-700,0,0")),
    ("V1500", ("V", "1500")), ("VL25000,25000,30000", ("VL", "25000,25000,30000")),
    ("VK", ("VK", "")), ("VN", ("VN", "")), ("XM200", ("XM", "200")), ("XA", ("XA", "")),
    ("$1", ("$", "1")), ("T24", ("T", "24")), ("MF", ("M", "F")), ("H", ("H", "")),
])
def test_a_frame_is_read_as_its_command_and_the_rest(body, read):
    assert _split(body) == read


@pytest.mark.parametrize(("body", "answer", "instead"), [
    ("A10000", b"5\r", "A20"),       # A's range is ours [D]: measured at reset
    ("A10000", b"0\r", None),        # taken
    ("A10000", b"4\r", None),        # another refusal: the case cannot judge
    ("A20", b"5\r", None),           # the reset value itself refused: nothing to fall back to
    ("V60000", b"5\r", None),        # V's range the manual states [M]
    ("L10,0,0", b"5\r", None),       # not a modal value
])
def test_only_a_range_no_manual_states_falls_back_to_the_reset_value(body, answer, instead):
    r = parse_response(answer, summed=False)
    assert _stated_instead(body, r, load_profile("GVE54")) == instead


def test_an_l_refused_with_1_while_a_dwell_holds_the_queue_is_sent_again_until_taken():
    """A unit holding RUN for the T dwell after `L0,0,0` (reading zero-vector-dwells)
    refuses the scenario's next `L` with 1 ("fronta před ním není hotová") until the
    dwell is over: sent again each tick, it is taken; an `L` refused while a vector still
    runs past the longest T keeps its refusal (the case then cannot judge)."""
    profile = load_profile("GVE84-100")
    unit = used_unit("GVE84-100", max_travel=4000, readings=("zero-vector-dwells",))
    session = unit.begin()
    try:
        link = session.open_link()
        assert link.send("T24").ok and link.send("L0,0,0").ok
        refused = link.send("L10,0,0")
        assert refused.code == 1
        began = link.now
        taken = _when_done(link, "L10,0,0", refused, profile)
        assert taken.ok and link.now - began < 0.03 * 1e9
        assert link.send("V40").ok
        # taken once the L10 and its dwell are over, then running for 1 s at V40
        assert link.poll("L40,0,0", lambda r: r.ok, 1.0) is not None
        refused = link.send("L10,0,0")
        assert _when_done(link, "L10,0,0", refused, profile).code == 1
    finally:
        session.finish()


def test_the_rest_before_a_scenario_is_booked_as_the_manuals_dwell():
    """The probe's rest before its first reading waits out the longest dwell T the
    manual allows a vector: the manual's wait in the run's time account, not the
    suite's own."""
    result = run([parse_target("emu:GVE84-100")], select(["10.2.measured.path-rate"]))
    (totals,) = [s["time"] for s in result.sessions.values()]
    assert load_profile("GVE84-100").range("T").hi / 1000 <= SETTLE
    assert totals[str(Spent.MANUAL)] == pytest.approx(SETTLE)
    assert totals[str(Spent.WAITS)] == 0
