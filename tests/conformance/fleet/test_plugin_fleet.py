"""Fleets under pytest-xdist: with several --gve-target, each target
that holds a port runs on one worker only, and two emulated units on two TCP ports run
in parallel under ``pytest -n 2`` with no errors."""

from __future__ import annotations

import re
import subprocess
import sys

import pytest

from conformance.pytest_plugin.plugin import worker_group
from conformance.targets import parse_target

pytest.importorskip("xdist", reason="pytest-xdist (the dev extra) runs the fleets")

#: quick cases that need no motion beyond the real-unit envelope
CASES = ["5.errors.*"]


def test_two_tcp_units_run_in_parallel_on_two_workers(tcp_units, tmp_path):
    ports = [tcp_units("--model", "GVE84-100"), tcp_units("--model", "GVE84-100")]
    argv = [sys.executable, "-m", "pytest", "-p", "no:cacheprovider", "-n", "2", "-v",
            "--gve-profile", "GVE84-100", "--gve-yes"]
    for where in ports:
        argv += ["--gve-target", f"tcp:{where}"]
    for glob in CASES:
        argv += ["--gve-cases", glob]
    done = subprocess.run(argv, cwd=tmp_path, capture_output=True, text=True, timeout=300,
                          check=False)
    out = done.stdout + done.stderr
    assert done.returncode == 0, out
    # "[gw1] [ 50%] PASSED gve/GVE84-100/section5::5.errors.ok[tcp:127.0.0.1:40001]@gve-..."
    ran = re.findall(r"\[(gw\d+)\] \[[ \d%]+\] (\w+) \S+::\S+\[tcp:([\d.:]+)\]", out)
    workers = {where: {w for w, _, port in ran if port == where} for where in ports}
    assert all(len(w) == 1 for w in workers.values()), workers     # a port, one worker
    assert workers[ports[0]] != workers[ports[1]]                   # in parallel
    outcomes = {outcome for _, outcome, _ in ran}
    assert "PASSED" in outcomes and outcomes <= {"PASSED", "SKIPPED"}, outcomes


def test_a_target_with_a_port_is_one_group_and_the_emulator_none():
    tcp = parse_target("tcp:127.0.0.1:5114", profile="GVE84-100")
    ipv6 = parse_target("tcp:[::1]:5114", profile="GVE84-100")
    serial = parse_target("serial:/dev/ttyUSB0?baud=9600", profile="GVE84-100")
    assert worker_group(parse_target("emu:GVE84-100")) is None    # a fresh unit per link
    assert worker_group(tcp) == "gve-port:socket://127.0.0.1:5114"
    # xdist takes the group after a node ID's last '@', past its last ']'
    assert all(c not in worker_group(ipv6) for c in "@[]")
    assert "/dev/ttyUSB0" in worker_group(serial)
    assert worker_group(tcp) != worker_group(parse_target("tcp:127.0.0.1:5115",
                                                          profile="GVE84-100"))
