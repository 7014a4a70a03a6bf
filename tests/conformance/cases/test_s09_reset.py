"""The MPG cases judge a `Y&` sent where EEPROM 06 does not allow the MPG by our reading
[D]: M114 13.6.8 says of a `Y&` sent that it holds RUN, 12.2 that the MPG is not allowed."""

from __future__ import annotations

import shlex
import sys
from pathlib import Path

from conformance.run.runner import run
from conformance.run.selection import select
from conformance.targets import parse_target
from conformance.verdicts.verdict import NON_STRICT
from gve_fixtures.profile import load_profile

CORPUS = Path(__file__).resolve().parents[3] / "corpus"
#: a simulator written from M114 alone whose `Y&` holds RUN whatever EEPROM 06 holds
SENT_HOLDS_RUN = [sys.executable, str(CORPUS / "gve114-d" / "sim.py"), "--cosim",
                  "--model", "GVE114-500"]


def test_a_y_sent_holding_run_where_the_mpg_is_not_allowed_is_our_readings_point():
    target = parse_target("exec:" + shlex.join(SENT_HOLDS_RUN), profile="GVE114-500",
                          allow_destructive=True,
                          max_travel=load_profile("GVE114-500").vector_range)
    target.preflight()
    result = run([target], select(["9.reset.mpg-enabling-values"]))
    [case] = result.results
    assert case.verdict == NON_STRICT
    failed = {c["rule"] for c in case.failed_checks}
    # a vector after J is still taken there: only the `Y&` sent differs
    assert "9.reset.mpg-inert" in failed and "9.reset.mpg" not in failed, failed
