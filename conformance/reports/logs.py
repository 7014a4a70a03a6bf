"""What the reports keep of long lists (issue 12 item 6): a case's wire log whole when it
did not PASS, a short head and tail when it did; its failed checks always, its passed
checks folded to a head and tail when there are many (a GVE114's full queue is 2048 of
them). ``--full-logs`` keeps everything."""

from __future__ import annotations

from conformance.verdict import PASS

#: items kept at each end of a folded list
HEAD = TAIL = 4


def _fold(items: list, marker) -> list:
    if len(items) <= HEAD + TAIL + 1:
        return list(items)
    return [*items[:HEAD], marker(len(items) - HEAD - TAIL), *items[-TAIL:]]


def compact(lines: list[str], verdict: str, full: bool = False) -> list[str]:
    """The lines of a wire log as a report shows them."""
    if full or verdict != PASS:
        return list(lines)
    return _fold(lines, lambda n: f"... {n} lines left out (the whole log: --full-logs) ...")


def compact_checks(checks: list[dict], full: bool = False) -> list[dict]:
    """A case's checks as a report shows them: every failed one; of a long run of passed
    ones the first and last few and one line saying how many are left out."""
    if full:
        return list(checks)
    out: list[dict] = []
    run: list[dict] = []
    for c in [*checks, None]:
        if c is not None and c["ok"]:
            run.append(c)
            continue
        out += _fold(run, lambda n: {"ok": True, "what": f"... {n} more passed checks "
                                     "(all of them: --full-logs) ...", "observed": "",
                                     "expected": "", "tag": "", "rule": ""})
        run = []
        if c is not None:
            out.append(c)
    return out
