"""The runner on toy cases: each way a case can end gets the verdict of docs/suite.md."""

from __future__ import annotations

import dataclasses

import pytest

from conformance.case.context import Case, CouldNotTest, Missing
from conformance.run.runner import run_case
from conformance.targets import parse_target
from conformance.verdicts.verdict import (
    COULD_NOT_TEST,
    ERROR,
    FAIL,
    INFO,
    MISSING,
    NON_STRICT,
    PASS,
)

#: a rule of each tag: every check names its rule, and is graded by its tag
RULE_OF = {"M": "5.code.ok", "M-ex": "5.code.range", "D": "3.frame.upper-case",
           "D-info": "10.3.st6.free"}


def _toy(body, tag="M", **kw) -> Case:
    return Case("99.toy.case", body, rule="toy rule", tag=tag, source="test",
                rules=(RULE_OF[tag],), **kw)


def _status_word(ctx):
    # spec: an in-range status word read answers code 0 with one value
    r = ctx.link.send("SR0")
    ctx.expect(r.code == 0 and len(r.values) == 1, "SR0 answers one value", observed=r)


def _fails(ctx):
    ctx.expect(False, "a check that fails")


def _raises(exc):
    def body(ctx):
        ctx.link.send("SR0")
        raise exc
    return body


@pytest.fixture
def target():
    return parse_target("emu:GVE84-100")


@pytest.mark.parametrize(("body", "tag", "verdict"), [
    (_status_word, "M", PASS),
    (_fails, "M", FAIL),
    (_fails, "M-ex", FAIL),
    (_fails, "D", FAIL),              # the emulator's profile implements the [D] rules
    (_fails, "D-info", INFO),
    (_raises(CouldNotTest("no rig")), "M", COULD_NOT_TEST),
    (_raises(Missing("no such command")), "M", MISSING),
    (_raises(RuntimeError("suite bug")), "M", ERROR),
    (lambda ctx: None, "M", ERROR),   # a case that recorded no check cannot fail: a defect
])
def test_each_ending_has_its_verdict(target, body, tag, verdict):
    assert run_case(_toy(body, tag), target).verdict == verdict


def _reads_garbage(index):
    def body(ctx):
        ctx.link.inject("unit", "corrupt", at=2, xor=0x40)   # 0,00 -> 0,p0
        r = ctx.link.send("SR0")
        r.hex(index)                                         # the unit's fault, not ours
    return body


@pytest.mark.parametrize("index", [0, 3])
def test_unit_bytes_that_cannot_be_read_fail_the_case_never_error(target, index):
    r = run_case(_toy(_reads_garbage(index), "D-info"), target)
    assert r.verdict == FAIL
    assert "cannot be read" in r.failed_checks[0]["what"] and "0,p0" in \
        r.failed_checks[0]["what"]


def test_d_is_non_strict_on_a_target_not_graded_strictly(target):
    target.info = dataclasses.replace(target.info, strict=False)
    assert run_case(_toy(_fails, "D"), target).verdict == NON_STRICT


def test_d_fails_on_the_reference_emulator_and_on_a_target_run_with_strict(target):
    assert target.info.strict and run_case(_toy(_fails, "D"), target).verdict == FAIL
    real = parse_target("tcp:localhost:1", profile="GVE84-100", strict=True)
    assert real.info.strict
    assert not parse_target("tcp:localhost:1", profile="GVE84-100").info.strict


def test_profile_filters_come_before_running(target):
    ran = []
    lacking = _toy(lambda ctx: ran.append(1), requires=("NOSUCH",))
    assert run_case(lacking, target).verdict == MISSING and not ran


def test_the_wire_log_and_frames_are_kept(target):
    r = run_case(_toy(_status_word), target)
    assert r.frames >= 1 and any("SR0" in line for line in r.wire_log)


def test_destructive_cases_wait_for_permission_on_real_units():
    real = parse_target("tcp:localhost:1", profile="GVE84-100")
    r = run_case(_toy(_fails, destructive=True), real)
    assert r.verdict == COULD_NOT_TEST and r.frames == 0


def test_one_id_for_two_different_cases_is_refused():
    from conformance.case.context import REGISTRY, case
    try:
        case("99.toy.twice", rules=("5.code.ok",))(_fails)
        with pytest.raises(ValueError, match="registered twice"):
            case("99.toy.twice", rules=("5.code.ok",))(_status_word)
    finally:
        REGISTRY.pop("99.toy.twice", None)
