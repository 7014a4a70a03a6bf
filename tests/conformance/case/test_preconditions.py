"""The features configured in EEPROM that cases rely on are data: every parameter the
manual names for each, the values it allows, a value to write that it allows."""

from __future__ import annotations

from conformance.case.preconditions import features
from gve_fixtures.profile import load_profile


def test_the_hand_wheel_needs_every_parameter_its_manual_names_with_the_enable_last():
    # M114 12.4-12.9: limits, steps per mm (X, Y, Z, A), acceleration, top speed, delay,
    # default spindle speed, step size: "if any parameter is out of range, the MPG cannot
    # be used", read for every parameter of the chapter's table with a range; 06 enables it
    params = features()["mpg"].params_for(load_profile("GVE114-500"))
    assert [p.address for p in params] == [*range(0x10, 0x40, 4), 0x40, 0x44, 0x48, 0x4C,
                                           0x60, 0x06]
    spindle = params[-3]
    assert spindle.write() == "EUW4C,500" and spindle.holds(["1000"]) \
        and not spindle.holds(["0"]) and not spindle.holds(["4294967295"])
    assert features()["mpg"].params_for(load_profile("GVE84-100")) == ()


def test_a_value_is_read_as_the_unit_writes_it():
    (enable,) = features()["mpg-off"].params
    assert enable.read() == "ER06" and enable.write() == "EW06,FF"
    assert enable.holds(["FF"]) and enable.holds(["00"]) and not enable.holds(["01"])
    assert not enable.holds(["1"]) and not enable.holds([])
    delay = next(p for p in features()["mpg"].params if p.address == 0x48)
    assert delay.write() == "EUW48,100" and delay.holds(["2000"]) and not delay.holds(["0"])
    speed = next(p for p in features()["mpg"].params if p.address == 0x44)
    assert speed.holds(["1.5e+01"]) and not speed.holds(["nan"]) and not speed.holds(["inf"])
    assert speed.shown == "MPG top speed (EEPROM 44: 0.001..125)"


def test_every_value_written_is_one_its_parameter_allows():
    for f in features().values():
        assert all(p.holds([p.text(p.value)]) for p in f.params), f.name
