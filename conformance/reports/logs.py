"""What the reports keep of a case (the default run's three reports must stay
under 2 MB): a case that did not PASS whole; of a passing case the head and tail of
its wire log, its first check and how many more passed (a GVE114's full queue is 2048 of
them) and no trace data (the page draws its traces). ``--full-logs`` keeps everything."""

from __future__ import annotations

from conformance.verdicts.check import Check
from conformance.verdicts.verdict import PASS

#: lines kept at each end of a passing case's wire log (its first frame, its last answer)
LOG_ENDS = 1


def _fold(items: list, ends: int, marker) -> list:
    if len(items) <= 2 * ends + 1:
        return list(items)
    return [*items[:ends], marker(len(items) - 2 * ends), *items[-ends:]]


def compact(lines: list[str], verdict: str, full: bool = False) -> list[str]:
    """The lines of a wire log as a report shows them."""
    if full or verdict != PASS:
        return list(lines)
    return _fold(lines, LOG_ENDS,
                 lambda n: f"... {n} lines left out (the whole log: --full-logs) ...")


def compact_checks(checks: list[dict], verdict: str, full: bool = False, *,
                   said: bool = True) -> list[dict]:
    """A case's checks as a report shows them: all of them unless the case passed (then
    every one passed); of a passing case's the first and (``said``) one line saying how
    many more passed — data that carries the count itself leaves that line out."""
    if full or verdict != PASS or len(checks) <= 1:
        return list(checks)
    if not said:
        return [checks[0]]
    return [checks[0], Check(True, f"... and {len(checks) - 1} more passed checks (all of "
                              "them: --full-logs) ...").to_dict()]

def compact_traces(traces: list[dict], verdict: str, full: bool = False) -> list[dict]:
    """A case's traces as the JSON keeps them: whole unless the case passed (the page
    draws a passing case's once)."""
    return list(traces) if full or verdict != PASS else []
