"""docs/ci.md's CI job for a firmware-clone author, run as written
against the emulator standing in for the clone's simulator: the suite runs, the JUnit
XML and the HTML report are published, the job ends with the suite's status. The
install block runs in the slow packaging tests (a fresh environment from the wheel)."""

from __future__ import annotations

import os
import socket
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from tests.conformance.fleet.recipe import blocks, commands, run_recipe
from tests.conformance.fleet.services import free_port

EMULATOR = f"{sys.executable} -m emulator --model GVE84-100"


def environment(port: int, simulator: str, cases: str) -> dict[str, str]:
    # the suite of this checkout's environment stands for the installed one
    bin_dir = str(Path(sys.executable).parent)
    return {"PATH": f"{bin_dir}:{os.environ.get('PATH', '')}", "GVE_PROFILE": "GVE84-100",
            "GVE_SIMULATOR": simulator, "GVE_PORT": str(port), "GVE_ARGS": f"--cases {cases}"}


def published(folder: Path) -> ET.Element:
    artifacts = folder / "artifacts"
    assert (artifacts / "gve-report" / "report.html").is_file()
    assert (artifacts / "gve-report" / "results.json").is_file()
    return ET.parse(artifacts / "junit.xml").getroot()


def test_the_shell_job_runs_a_tcp_simulator_and_publishes(tmp_path):
    port = free_port()
    env = environment(port, f"{EMULATOR} --tcp 127.0.0.1:{port}", "5.errors.*")
    done = run_recipe(["settings", "run-tcp", "publish"], tmp_path, env)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "PASSED" in done.stdout
    assert len(published(tmp_path).findall("./testsuite/testcase")) > 0
    # the recipe stopped the simulator when it ended
    with pytest.raises(OSError), socket.create_connection(("127.0.0.1", port), timeout=2):
        pass


def test_the_shell_job_runs_an_exec_simulator_and_publishes(tmp_path):
    pidfile = tmp_path / "simulator.pid"
    simulator = f"sh -c 'echo $$ > {pidfile}; exec {EMULATOR} --pty'"
    env = environment(0, simulator, "5.errors.*")
    done = run_recipe(["settings", "run-exec", "publish"], tmp_path, env)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "PASSED" in done.stdout
    assert len(published(tmp_path).findall("./testsuite/testcase")) > 0
    # the suite stopped the simulator it started
    with pytest.raises(ProcessLookupError):
        os.kill(int(pidfile.read_text()), 0)


def test_the_shell_job_runs_a_co_simulator_in_virtual_time_and_publishes(tmp_path):
    env = {**environment(0, "", "5.errors.*"), "GVE_COSIM": f"{EMULATOR} --cosim",
           "GVE_DIFF_SECONDS": "2"}
    done = run_recipe(["settings", "run-cosim", "publish"], tmp_path, env)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "PASSED" in done.stdout and "diff: exec:" in done.stdout
    assert len(published(tmp_path).findall("./testsuite/testcase")) > 0
    assert list((tmp_path / "artifacts" / "gve-diff").glob("*/results.json"))


def test_a_co_simulator_s_failure_fails_the_job(tmp_path):
    env = {**environment(0, "", "10.2.measured.cruise-at-v"),
           "GVE_COSIM": f"{EMULATOR} --cosim --mutant velocity-ignored",
           "GVE_DIFF_SECONDS": "2"}
    done = run_recipe(["settings", "run-cosim", "publish"], tmp_path, env)
    assert done.returncode == 1, done.stdout + done.stderr
    assert (tmp_path / "artifacts" / "gve-report" / "report.html").is_file()


def test_the_github_workflow_runs_the_shell_job_s_commands():
    recipe = blocks()
    workflow = [line.removesuffix(" || status=$?") for line in commands(recipe["github"])]
    for step in ("install", "run-exec", "run-cosim"):
        for line in commands(recipe[step]):
            if line.startswith(("python3 -m venv", ". ", "status=")):
                continue        # the workflow's Python is set up by actions/setup-python
            assert line.removesuffix(" || status=$?") in workflow, line
