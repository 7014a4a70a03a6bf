"""A host that is not a Python program — a few lines of shell around the port — is judged
the same way."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from junitparser import Failure, JUnitXml, Properties, Skipped

from conformance.verdicts.verdict import FAIL, NON_STRICT, PASS
from tests.conformance.host.run import certify, failing_rules, verdicts

pytestmark = [pytest.mark.pty,
              pytest.mark.skipif(shutil.which("bash") is None or shutil.which("stty") is None,
                                 reason="needs bash and stty")]

SCRIPT = str(Path(__file__).with_name("shell_host.sh"))


def test_a_shell_host_passes_the_clean_line_and_gives_up_on_a_lost_answer(tmp_path):
    status, results = certify(tmp_path, "GVE84-100", command=[SCRIPT, "{port}"],
                              scenarios=("lost-answer.vector",))
    found = verdicts(results)
    print(found)
    assert found["clean"] == PASS
    # no recovery: it stops honestly (exit 3) with the motion a beginning of the job's
    assert found["lost-answer.vector"] == NON_STRICT and status == 0
    lost = next(r for r in results if r["scenario"] == "lost-answer.vector")
    assert {c["rule"] for c in lost["checks"] if not c["ok"]} == {"8.recovery.finishes"}


def test_a_shell_host_in_lower_case_fails(tmp_path):
    status, results = certify(tmp_path, "GVE84-100", command=[SCRIPT, "{port}", "lower"],
                              scenarios=("clean",))
    clean = results[0]
    print(clean["verdict"], failing_rules(clean))
    assert status == 1 and clean["verdict"] == FAIL
    assert "5.code.unknown" in failing_rules(clean)


@pytest.mark.parametrize("strict", [False, True])
def test_the_junit_file_tells_a_ci_the_non_strict_verdict(tmp_path, strict):
    certify(tmp_path, "GVE84-100", command=[SCRIPT, "{port}"], scenarios=("lost-answer.vector",),
            options=("--strict",) if strict else ())
    (folder,) = [p for p in tmp_path.iterdir() if p.is_dir()]
    (suite,) = JUnitXml.fromfile(str(folder / "junit.xml"))
    (lost,) = [c for c in suite if c.name.startswith("8.host.lost-answer.vector")]
    verdict = {p.name: p.value for p in lost.child(Properties)}["verdict"]
    if strict:      # the host claims the project's decisions: the [D] rule FAILs
        (failure,) = lost.result
        assert isinstance(failure, Failure) and verdict == FAIL
        assert failure.message.startswith("FAIL: 8.recovery.finishes [D] ")
    else:       # neither passed nor failed: skipped, saying why first
        (skipped,) = lost.result
        assert isinstance(skipped, Skipped) and verdict == NON_STRICT
        assert skipped.message.startswith("NON-STRICT: 8.recovery.finishes [D] ")
        assert lost.system_out.startswith(skipped.message)
