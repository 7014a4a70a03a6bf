"""The MPG cases judge a `Y&` sent where EEPROM 06 does not allow the MPG by our reading
[D]: M114 13.6.8 says of a `Y&` sent that it holds RUN, 12.2 that the MPG is not allowed."""

from __future__ import annotations

from conformance.verdicts.verdict import NON_STRICT
from tests.conformance.cases.corpus_unit import case_on


def test_a_y_sent_holding_run_where_the_mpg_is_not_allowed_is_our_readings_point():
    # gve114-d, written from M114 alone: its `Y&` holds RUN whatever EEPROM 06 holds
    case = case_on("gve114-d", "GVE114-500", "9.reset.mpg-enabling-values")
    assert case.verdict == NON_STRICT
    failed = {c["rule"] for c in case.failed_checks}
    # a vector after J is still taken there: only the `Y&` sent differs
    assert "9.reset.mpg-inert" in failed and "9.reset.mpg" not in failed, failed
