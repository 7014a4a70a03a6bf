"""The end of every job, as a person reads it on the console or in a CI log: the line of
a FAIL names the check that decided it (a broken manual's rule, not a decision that
failed first), its rule and tag; the recap lists what failed again with the rule's
sentence, then where the reports are and the verdict, under -q too. When the reports
cannot be written (a full disk: a tmpfs of a few kilobytes, else a report folder whose
writes fail) the run ends with its unit restored, one line naming the file and the
error, a non-zero exit status, no truncated results.json and no traceback; a --run-id
taken by another run is refused with one line before anything is sent, that run's
reports untouched."""

from __future__ import annotations

import contextlib
import errno
import io
import json
import os
import shutil
import subprocess
import sys

import pytest

from conformance.cli import main
from conformance.reports import files
from conformance.verdicts.explain import plain
from gve_fixtures.rules import load_rules
from tests.conformance.safety.proxy import unit_behind_proxy

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
        assert rule.tag == "M" \
            and recap[3].strip() == f"the rule: {plain(rule.text)} ({plain(rule.source)})"
    quiet = outs[True]
    assert quiet[0].startswith("what failed")            # -q: nothing before the recap


QUICK = ["--target", "emu:GVE54", "--cases", "5.errors.ok"]
#: a real unit (the emulator on a pty), its session's restorations printed
REAL = ["--profile", "GVE84-100", "--yes", "--max-travel", "500", "--cases", "5.errors.*"]


def _complete(folder) -> None:
    """No partial file; whatever results.json there is parses."""
    for path in folder.rglob("*"):
        assert not path.name.endswith(".partial"), path
        if path.name == "results.json":
            json.loads(path.read_text())


def test_the_same_run_id_twice_is_refused_and_loses_nothing(tmp_path, capsys):
    argv = [*QUICK, "--report-dir", str(tmp_path), "--run-id", "nightly"]
    assert main(argv) == 0
    results = tmp_path / "nightly" / "results.json"
    before = results.read_bytes()
    capsys.readouterr()
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--run-id nightly" in err and "exists" in err, err
    assert results.read_bytes() == before


def test_a_refused_run_gives_its_fresh_folder_back(tmp_path, capsys):
    argv = [*QUICK, "--report-dir", str(tmp_path), "--run-id", "again", "--mutant", "nosuch"]
    assert main(argv) == 2
    assert not (tmp_path / "again").exists(), "nothing written: the id is free again"


@pytest.mark.pty
def test_reports_that_cannot_be_written_end_the_run_with_one_line(tmp_path, capsys,
                                                                  monkeypatch):
    written = []

    def second_fails(fd: int) -> None:        # junit.xml goes, results.json does not
        written.append(fd)
        if len(written) == 2:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(files.os, "fsync", second_fails)
    with unit_behind_proxy("--model", "GVE84-100") as (emu, proxy):
        status = main(["--target", f"serial:{proxy.path}", *REAL,
                       "--report-dir", str(tmp_path), "--run-id", "full"])
        state = emu.state()
    captured = capsys.readouterr()
    assert status == 1
    assert captured.err.count("\n") == 1, captured.err
    assert f"cannot write {tmp_path}/full/results.json: No space left on device" in captured.err
    assert "restored: ST0..ST5 written back and read back as found" in captured.out, \
        "restored before the reports"
    assert captured.out.splitlines()[-1].startswith(("PASSED", "INCOMPLETE")), \
        "the verdict still said"
    assert state["status"][:6] == ["00"] * 6
    assert not (tmp_path / "full" / "results.json").exists()
    _complete(tmp_path)


@pytest.mark.pty
def test_a_full_tmpfs_ends_the_run_with_one_line(tmp_path):
    """A real full disk: a tmpfs of 16 KiB in a mount namespace of the run's own."""
    unshare = shutil.which("unshare")
    reports = tmp_path / "reports"
    reports.mkdir()
    probe = subprocess.run([unshare or "unshare", "-rm", "mount", "-t", "tmpfs", "-o",
                            "size=16k", "tmpfs", str(reports)], capture_output=True)
    if unshare is None or probe.returncode != 0:
        pytest.skip("no mount namespace for a tmpfs here (the test above fails the writes "
                    f"instead): {probe.stderr.decode(errors='replace').strip()}")
    with unit_behind_proxy("--model", "GVE84-100") as (emu, proxy):
        script = (f"mount -t tmpfs -o size=16k tmpfs {reports} && exec {sys.executable} -m "
                  f"conformance --target serial:{proxy.path} {' '.join(REAL)} --cases '8.*' "
                  f"--full-logs --report-dir {reports} --run-id full")
        done = subprocess.run([unshare, "-rm", "sh", "-c", script], capture_output=True,
                              text=True, timeout=300, stdin=subprocess.DEVNULL)
        state = emu.state()
    assert done.returncode == 1, done.stdout + done.stderr
    assert "Traceback" not in done.stdout + done.stderr
    assert done.stderr.count("\n") == 1 and "No space left on device" in done.stderr, \
        done.stderr
    assert f"cannot write {reports}/full/" in done.stderr
    assert "restored: ST0..ST5 written back and read back as found" in done.stdout
    assert state["status"][:6] == ["00"] * 6


def test_the_recap_lists_by_section_number_and_non_strict_apart():
    from conformance.cli.ending import recap
    from conformance.run.runner import RunResult
    from tests.conformance.reports.toy import result
    run = RunResult("toy", [result("11.golden.g1", "FAIL"), result("8.repeat.answer",
                                                                    "NON-STRICT"),
                            result("6.checksum.wrong", "FAIL"), result("10.10.x.y", "FAIL"),
                            result("10.2.x.y", "FAIL")], ["emu:GVE84-100"])
    heads = [line for line in recap(run) if not line.startswith((" ", "FAIL", "NON-"))]
    listed = [line.split()[1] for line in recap(run) if line.startswith(("FAIL", "NON-"))]
    assert heads == ["what failed (4):",
                     "what departs from the project's decisions, NON-STRICT (1):"]
    assert listed == ["6.checksum.wrong", "10.2.x.y", "10.10.x.y", "11.golden.g1",
                      "8.repeat.answer"]


def test_a_count_of_missing_says_it_is_nothing_to_test():
    from conformance.cli.ending import counted
    from conformance.run.runner import RunResult
    from tests.conformance.reports.toy import result
    run = RunResult("toy", [result("1.a.b", "PASS"), result("3.params.float-values",
                                                           "MISSING")], ["emu:GVE54"])
    assert counted(run) == "MISSING 1 (not in the profile: nothing to test), PASS 1"
