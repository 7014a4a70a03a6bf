"""The end of every job, as a person reads it on the console or in a CI log: the line of
a FAIL names the check that decided it (a broken manual's rule, not a decision that
failed first), its rule and tag; the recap lists what failed again with the rule's
sentence, then where the reports are and the verdict, under -q too."""

from __future__ import annotations

import contextlib
import io
import json

import pytest

from conformance.cli import main
from gve_fixtures.rules import load_rules

#: a parameter out of range is answered 4 instead of 5: it breaks the manual's `$` range
#: [M] and our reading of V's [D] alike, in one case, the [D] checks first
MUTANT = "emu:GVE84-100?mutant=range-error-code"
CASE = "1.profile.parameter-ranges"


@pytest.fixture(scope="module")
def mixed(tmp_path_factory):
    """The case run on the mutant: its console output (quiet and not) and its results."""
    folder = tmp_path_factory.mktemp("mixed")
    outs = {}
    for quiet in (False, True):
        run_id = "quiet" if quiet else "loud"
        argv = ["--target", MUTANT, "--cases", CASE, "--report-dir", str(folder),
                "--run-id", run_id] + (["-q"] if quiet else [])
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            assert main(argv) == 1
        outs[quiet] = out.getvalue().splitlines()
    (result,) = json.loads((folder / "loud" / "results.json").read_text())["results"]
    return outs, result, folder


def _tag(rule: str) -> str:
    return load_rules()[rule].tag


def test_the_fail_line_names_the_manual_rule_that_decided_it(mixed):
    outs, result, _ = mixed
    failed = [c for c in result["checks"] if not c["ok"]]
    assert _tag(failed[0]["rule"]) == "D"                 # a decision failed first
    assert "M" in {_tag(c["rule"]) for c in failed}       # and a manual's rule too
    (line,) = [line for line in outs[False] if line.startswith("[") and CASE in line]
    named = line.split("-- ", 1)[1].split()[0]
    assert _tag(named) == "M" and f"{named} [M] " in line
    assert named in {c["rule"] for c in failed}
    decided = next(c for c in failed if c["rule"] == named)
    assert f'observed "{decided["observed"]}", expected "{decided["expected"]}"' in line


def test_the_recap_lists_what_failed_with_the_rule_s_sentence_under_quiet_too(mixed):
    outs, _, folder = mixed
    for quiet, lines in outs.items():
        run_id = "quiet" if quiet else "loud"
        assert lines[-1].startswith("FAILED") and "1 FAIL" in lines[-1]
        assert lines[-2].startswith(f"reports: {folder / run_id}/report.html")
        start = lines.index(next(line for line in lines if line.startswith("what failed")))
        recap = lines[start:-2]
        assert CASE in recap[1] and recap[1].startswith("FAIL")
        named = recap[2].split()[0]
        rule = load_rules()[named]
        assert rule.tag == "M" and recap[3].strip() == f"the rule: {rule.text} ({rule.source})"
    quiet = outs[True]
    assert quiet[0].startswith("what failed")            # -q: nothing before the recap
