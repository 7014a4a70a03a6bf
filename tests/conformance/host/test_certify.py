"""The reference host passes every scenario: with checksums and packets on the GVE84, in
plain frames on the GVE54, one byte at a time at 921 600 baud on the GVE114.
Real time: the job is about a second of motion; the scenarios run side by side.
The whole matrix (every profile, every mode, every scenario) is marked slow."""

from __future__ import annotations

import sys

import pytest

from conformance.host.scenarios import SCENARIOS
from conformance.verdicts.verdict import FAIL, INFO, MISSING, PASS
from gve_fixtures.profile import available_profiles, load_profile
from tests.conformance.host.run import certify, verdicts

pytestmark = pytest.mark.pty


def test_every_scenario_with_checksums_and_packets(tmp_path):
    status, results = certify(tmp_path, "GVE84-100", "--checksums", "--packets", "4")
    found = verdicts(results)
    print(found)
    assert status == 0
    assert set(found) == {s.name for s in SCENARIOS}
    assert all(v == PASS for name, v in found.items() if name != "restart")
    assert found["restart"] in (PASS, INFO)                 # how the host reacts
    html = next(tmp_path.iterdir()).joinpath("report.html").read_text()
    # the wire log both ways, each injected fault marked on it
    assert "&gt; !0L1000,0,0," in html and "&lt; 0,5C\\r" in html
    for kind in ("lost-answer", "corrupt-answer", "late-answer", "noise", "queue-full",
                 "lost-frame", "cut-frame", "interrupt", "restart"):
        assert f"= fault {kind}" in html, kind
    clean = next(r for r in results if r["scenario"] == "clean")
    judged = set(clean["rules_judged"])
    assert {"2.link.simplex", "3.frame.watchdog", "6.checksum.sum", "7.packet.count",
            "5.code.queue-full", "2.link.serial-8n1"} <= judged


def test_plain_frames_on_the_gve54(tmp_path):
    status, results = certify(tmp_path, "GVE54", scenarios=(
        "lost-answer.vector", "noise.setting", "interrupt", "*.packet"))
    found = verdicts(results)
    print(found)
    assert status == 0
    assert found["clean"] == found["lost-answer.vector"] == found["noise.setting"] == PASS
    assert found["interrupt"] == PASS
    assert found["lost-answer.packet"] == MISSING           # no packets on the GVE54


def test_one_byte_at_a_time_at_921600_baud(tmp_path):
    status, results = certify(tmp_path, "GVE114-500", "--baud", "921600", "--char-gap", "1",
                              "--checksums", scenarios=("corrupt-answer.vector", "cut-frame"),
                              options=("--baud", "921600"))
    found = verdicts(results)
    print(found)
    assert status == 0 and set(found.values()) == {PASS}
    notes = " ".join(next(r for r in results if r["scenario"] == "clean")["notes"])
    assert "slowest gap between the bytes of a frame" in notes


MODES = [(), ("--checksums",), ("--checksums", "--packets", "3"), ("--char-gap", "3")]
#: every profile in every mode it has (the GVE54 has no checksums and no packets, spec 1)
MATRIX = [(p, m) for p in available_profiles() for m in MODES
          if not (load_profile(p).family == "GVE54" and "--checksums" in m)]


@pytest.mark.slow
@pytest.mark.parametrize(("profile", "mode"), MATRIX)
def test_the_whole_matrix(tmp_path, profile, mode):
    status, results = certify(tmp_path, profile, *mode)
    found = verdicts(results)
    print(profile, mode, found)
    assert status == 0
    assert all(v in (PASS, MISSING) for name, v in found.items() if name != "restart")


SLOW_HOST = """
import sys, time, serial
port = serial.serial_for_url(sys.argv[1], 115200, timeout=2)
port.write(b"!0?\\r")
port.read_until(b"\\r")
time.sleep(1)
"""


def test_the_clean_runs_limit_is_the_users(tmp_path):
    # a host whose job asks `?` and then takes a second: past a clean-run limit of 0.3 s
    # it is still running, a FAIL; under the default limit it finishes
    slow = [sys.executable, "-c", SLOW_HOST, "{port}"]
    status, results = certify(tmp_path / "short", "GVE84-100", scenarios=("2.host.clean",),
                              options=("--clean-limit", "0.3"), command=slow)
    (clean,) = results
    assert status == 1 and clean["verdict"] == FAIL
    assert any("still running" in c["observed"] and "--clean-limit" in c["observed"]
               for c in clean["checks"] if c["rule"] == "8.recovery.finishes")
    status, results = certify(tmp_path / "default", "GVE84-100", scenarios=("2.host.clean",),
                              command=slow)
    assert status == 0 and [r["verdict"] for r in results] == [PASS]
