"""The machines' example database: a failing example
found by one run is the first example of the next one, from a directory by default or
from a Redis server that several benches share; keys are per profile; a database that
cannot be used is a usage error before anything runs."""

from __future__ import annotations

import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from conformance.case.settings import DEFAULT_DATABASE, database_for, example_database
from conformance.cli import main
from tests.conformance.fleet.services import free_port

# a machine and a mutant it catches: every checksummed answer shows the mutant
CASE = "6.machine.checksum-framing"
MUTANT_TARGET = "emu:GVE84-100?mutant=checksum-lower-case"

pytest_plugins = ["pytester"]


def examples(junit: Path) -> list[list[str]]:
    """The host's frames of each example (each link) the machine ran, in order: the
    failing case's whole wire log, as its JUnit failure carries it."""
    (failure,) = ET.parse(junit).getroot().iter("failure")
    out: list[list[str]] = []
    for line in failure.text.splitlines():
        if line == "# link":
            out.append([])
        elif " > " in line:
            out[-1].append(line.split(" > ", 1)[1])
    return out


def without_index_measure(frames: list[str]) -> list[str]:
    """The frames with the index's reads folded: the first `@` of a unit whose answer does
    not show its form is read again between `SR6` frames that move it
    (conformance/protocol/index.py), once per unit, so only the example that first met it
    carries them; each run of `@` reads counts as one."""
    out: list[str] = []
    for f in frames:
        if f == "!0SR6\\r" or (f == "!0@\\r" and out and out[-1] == f):
            continue
        out.append(f)
    return out


def run_cli(folder: Path, run_id: str, *options: str) -> tuple[int, list[list[str]]]:
    """A run of the machine against the mutant (reports only as JUnit unless the
    options say otherwise): its status and its examples."""
    junit = folder / f"{run_id}.xml"
    status = main(["--target", MUTANT_TARGET, "--cases", CASE, "--report-dir", str(folder),
                   "--run-id", run_id, "--junitxml", str(junit), "-q", *options])
    return status, examples(junit)


def test_the_next_run_tries_the_failing_example_first(tmp_path):
    status, first = run_cli(tmp_path, "first")
    assert status == 1 and len(first) > 2          # a search, then shrinking
    # the default database: a folder beside the reports, keys per profile
    assert any((tmp_path / DEFAULT_DATABASE / "GVE84-100").iterdir())
    status, second = run_cli(tmp_path, "second")
    # the stored example first (it fails at once), then Hypothesis's replay of it
    assert status == 1 and len(second) == 2
    assert (without_index_measure(second[0]) == without_index_measure(first[-1])
            == without_index_measure(second[-1]))


def test_without_a_database_each_run_searches_again(tmp_path):
    _, first = run_cli(tmp_path, "first", "--no-reports")
    _, second = run_cli(tmp_path, "second", "--hypothesis-db", "none")
    assert second == first and len(second) > 2      # derandomized: the same search
    assert not (tmp_path / DEFAULT_DATABASE).exists()


def test_a_run_that_fails_nothing_leaves_no_database(tmp_path):
    assert main(["--target", "emu:GVE84-100", "--cases", CASE, "--report-dir", str(tmp_path),
                 "-q"]) == 0
    assert not (tmp_path / DEFAULT_DATABASE).exists()


def test_each_profile_has_keys_of_its_own(tmp_path):
    with example_database(str(tmp_path)):
        database_for("GVE84-100").save(b"machine", b"example")
        assert list(database_for("GVE84-100").fetch(b"machine")) == [b"example"]
        assert list(database_for("GVE114-500").fetch(b"machine")) == []


def test_a_database_that_cannot_be_used_is_a_usage_error(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    closed = f"redis://127.0.0.1:{free_port()}/0"
    for where in (str(blocker), str(blocker / "below"), closed):
        assert main(["--target", "emu:GVE84-100", "--cases", CASE, "--no-reports",
                     "--hypothesis-db", where]) == 2
        err = capsys.readouterr().err
        assert err.startswith("gve-conformance: --hypothesis-db:") and err.count("\n") == 1


def test_the_plugin_refuses_a_database_that_cannot_be_used(pytester):
    (pytester.path / "file").write_text("not a folder")
    result = pytester.runpytest("--gve-target", "emu:GVE84-100", "--gve-cases", CASE,
                                "--gve-hypothesis-db", "file")
    assert result.ret == pytest.ExitCode.USAGE_ERROR
    result.stderr.fnmatch_lines(["*--gve-hypothesis-db: example database file*"])


def test_benches_sharing_redis_try_each_others_failing_examples_first(tmp_path, redis_url):
    """Bench A finds a failing example; bench B, another process with another seed,
    runs it first; the same run as B without the database does not."""

    def bench(name: str, seed: str, database: str) -> list[list[str]]:
        junit = tmp_path / f"{name}.xml"
        done = subprocess.run(
            [sys.executable, "-m", "conformance", "--target", MUTANT_TARGET, "--cases", CASE,
             "--settings", "dev", "--seed", seed, "--hypothesis-db", database,
             "--no-reports", "--junitxml", str(junit), "-q"],
            capture_output=True, text=True, timeout=120, check=False)
        assert done.returncode == 1, done.stdout + done.stderr
        return examples(junit)

    a = bench("bench-a", "1", redis_url)
    from redis import Redis
    assert Redis.from_url(redis_url).keys("gve-example:GVE84-100:*")
    b = bench("bench-b", "2", redis_url)
    _, alone = run_cli(tmp_path, "bench-b-alone", "--settings", "dev", "--seed", "2",
                       "--no-reports")
    assert without_index_measure(b[0]) == without_index_measure(a[-1]) and len(b) == 2
    assert alone[0] != a[-1] and len(alone) > len(b)


def test_the_plugin_leaves_no_hypothesis_folder_in_the_working_directory(pytester):
    """Hypothesis's own cache goes to a temporary folder; the examples stay where the run
    keeps its database (none here: the machine fails nothing on the clean emulator)."""
    # in a process of its own: Hypothesis takes its default folder from the working
    # directory it was imported in
    result = pytester.runpytest_subprocess("--gve-target", "emu:GVE84-100", "--gve-cases",
                                           CASE, "-p", "no:cacheprovider")
    result.assert_outcomes(passed=1)
    assert not (pytester.path / ".hypothesis").exists()
    assert not (pytester.path / DEFAULT_DATABASE).exists()


def test_a_run_leaves_no_hypothesis_folder_in_the_working_directory(tmp_path):
    done = subprocess.run([sys.executable, "-m", "conformance", "--target", MUTANT_TARGET,
                           "--cases", CASE, "--report-dir", "reports", "-q"], cwd=tmp_path,
                          capture_output=True, text=True, timeout=300, check=False)
    assert done.returncode == 1, done.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["reports"]
    assert (tmp_path / "reports" / DEFAULT_DATABASE).is_dir()
