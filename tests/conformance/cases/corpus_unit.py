"""One case run on a simulator of corpus/ (written from a manual alone), as a user's
`exec:` target runs it: its result."""

from __future__ import annotations

import shlex
import sys
from pathlib import Path

from conformance.run.runner import CaseResult, run
from conformance.run.selection import select
from conformance.targets import parse_target
from gve_fixtures.profile import load_profile

CORPUS = Path(__file__).resolve().parents[3] / "corpus"


def case_on(simulator: str, profile: str, case_id: str) -> CaseResult:
    """``case_id`` on corpus/``simulator``/sim.py co-simulating ``profile``, within an
    envelope as wide as the profile's vectors."""
    argv = [sys.executable, str(CORPUS / simulator / "sim.py"), "--cosim", "--model", profile]
    target = parse_target("exec:" + shlex.join(argv), profile=profile, allow_destructive=True,
                          max_travel=load_profile(profile).vector_range)
    target.preflight()
    [case] = run([target], select([case_id])).results
    return case
