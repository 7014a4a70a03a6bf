"""serial: targets take any pyserial URL, its own options kept and the suite's (baud,
address) taken out; a plain path stays as given."""

from __future__ import annotations

import pytest

from conformance.targets import parse_target
from conformance.targets.port import locate


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
