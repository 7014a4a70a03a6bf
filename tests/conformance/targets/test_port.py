"""serial: targets take any pyserial URL, its own options kept and the suite's (baud,
address) taken out; a plain path stays as given."""

from __future__ import annotations

import pytest

from conformance.run.runner import run
from conformance.run.selection import select
from conformance.targets import TargetError, parse_target
from conformance.targets.port import locate
from conformance.verdicts.verdict import PASS


@pytest.mark.parametrize(("rest", "url", "ours"), [
    ("/dev/ttyUSB0?baud=38400&address=1", "/dev/ttyUSB0", {"baud": ["38400"],
                                                          "address": ["1"]}),
    ("COM3", "COM3", {}),
    ("rfc2217://10.0.0.5:2217?baud=115200&ign_set_control",
     "rfc2217://10.0.0.5:2217?ign_set_control=", {"baud": ["115200"]}),
    ("socket://127.0.0.1:5114?address=2", "socket://127.0.0.1:5114", {"address": ["2"]}),
    ("loop://?logging=debug", "loop://?logging=debug", {}),
])
def test_pyserial_urls_are_kept_whole(rest, url, ours):
    assert locate("serial", rest) == (url, ours)


def test_a_target_opens_what_pyserial_is_given():
    t = parse_target("serial:socket://127.0.0.1:5114?baud=38400&address=3",
                     profile="GVE84-100")
    assert (t.url, t.baud, t.address) == ("socket://127.0.0.1:5114", 38400, 3)
    assert parse_target("tcp:127.0.0.1:5114", profile="GVE54").url == "socket://127.0.0.1:5114"


@pytest.mark.parametrize("rest", ["", ":5114", "localhost", "h:notaport", "h:99999", "h:0",
                                  "h:5114/x", "user@h:5114"])
def test_a_tcp_target_needs_a_host_and_a_port(rest):
    # pyserial would take an empty host for this machine and a bad port only on connecting
    with pytest.raises(TargetError, match=r"tcp:HOST:PORT \(a port 1\.\.65535\)"):
        parse_target(f"tcp:{rest}", profile="GVE84-100")


@pytest.mark.parametrize(("rest", "url"), [
    ("127.0.0.1:5114", "socket://127.0.0.1:5114"),
    ("sim.local:65535?address=2", "socket://sim.local:65535"),
    ("[::1]:5114", "socket://[::1]:5114"),
])
def test_a_tcp_target_with_a_host_and_a_port(rest, url):
    assert parse_target(f"tcp:{rest}", profile="GVE84-100").url == url


def test_the_emulator_s_own_url_is_a_unit_on_a_port_in_real_time():
    """`serial:gve://…` (the handler the project ships) opens, in real time, and is judged
    as a unit that is not the suite's own: the known state, the envelope, the grading."""
    t = parse_target("serial:gve://?model=GVE84-100&address=3", profile="GVE84-100")
    assert t.url == "gve://?model=GVE84-100&address=3&realtime=1" and t.address == 3
    t.preflight()
    try:
        result = run([t], select(["5.errors.ok"]))
    finally:
        t.close()
    assert [r.verdict for r in result.results] == [PASS]
    assert t.info.real


def test_the_emulator_s_url_in_virtual_time_points_to_the_targets_that_run_it_so():
    with pytest.raises(TargetError, match="emu:MODEL"):
        parse_target("serial:gve://?model=GVE84-100&realtime=0", profile="GVE84-100")
