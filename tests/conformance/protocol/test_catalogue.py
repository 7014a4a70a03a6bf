"""The command catalogue: read whole, one entry per command of spec 10, the facts the
spec states (section 2, 7, 8, 10.6) where the readers of the suite take them from."""

from __future__ import annotations

import pytest

from conformance.protocol import catalogue as cat
from gve_fixtures.profile import KNOWN_COMMANDS


def test_the_catalogue_names_every_command_a_profile_may_have():
    assert {c.known_as for c in cat.commands().values()} == KNOWN_COMMANDS
    assert cat.commands()["O"].known_as == "O0"


def test_a_write_of_st6_is_its_own_class_and_acts_on_motion():
    sw6, sw = cat.catalogue()["SW6"], cat.catalogue()["SW"]
    assert sw6.fields == sw.fields
    assert sw6.motion and sw6.stops and not sw.motion
    assert "SW6" not in cat.commands()


def test_packet_roles_follow_spec_7():
    assert cat.classes(packet="opens") == {"*S"}
    assert cat.classes(packet="member") == {"C", "B"}
    assert cat.classes(packet="breaker") == {"H", "@", ">", "J"}
    assert cat.classes(packet="closes") == {"*E"}
    assert {n for n, c in cat.catalogue().items() if c.ends_packet} == {"H", "@", ">", "J", "*E"}


def test_answers_follow_spec_2_and_8():
    assert cat.classes(deferred=True) == {"H", "W"}
    assert cat.classes(restart=True) == {"J"}
    assert cat.classes(indexed=False) == {"@", ">"}
    assert cat.classes(remembered=False) == {"@", ">", "*S"}
    assert cat.classes(answer=False) == {"*S"}
    assert cat.catalogue()[">"].lines == 2


def test_what_commands_do_to_a_motion_follows_spec_10():
    assert cat.classes(vector=True) == {"L", "C"}
    assert cat.classes(exchanges=True) == {"XA", "XU", "XD"}
    assert cat.classes(paces=True) == {"V", "A", "VL", "XM"}
    assert cat.classes(own_speed=True) == {"W", "Y"}
    assert cat.classes(empties=True) == {"D", "K"}
    assert cat.classes(still=True) == {"D", "K", "R"}
    assert cat.classes(resumes="queue") == {"G", "SW6"}
    assert cat.classes(resumes="save") == {"R"}
    assert cat.classes(switch=True) == {"VK", "VN"}


def test_the_pure_reads_read_and_set_nothing():
    queries = cat.classes(query=True)
    assert queries == {"?", "Q", "P", "PF", "ER", "EFR", "EUR", "I0", "I1", "I2", "SR", "F",
                       "@", ">"}
    sets = ("vector", "motion", "marks", "stops", "restart", "empties", "modal", "setting",
            "eeprom", "checksums", "exchanges", "course", "retimes", "paces", "reaction",
            "destructive", "own_speed", "summing")
    for name in queries:
        c = cat.catalogue()[name]
        assert c.repeatable and c.packet in (None, "breaker"), name
        assert not any(getattr(c, flag) for flag in sets), name


def test_an_unknown_resumed_place_is_refused(tmp_path):
    path = tmp_path / "commands.toml"
    path.write_text('[command.G]\nresumes = "stack"\n', encoding="utf-8")
    with pytest.raises(ValueError, match="resumes"):
        cat.catalogue(path)


def test_eeprom_writes_and_their_widths():
    assert {n: cat.eeprom_width(n) for n in ("EW", "EFW", "EUW", "ER", "nope")} == {
        "EW": 1, "EFW": 4, "EUW": 4, "ER": 0, "nope": 0}
    assert cat.classes(destructive=True) == {"J", "W", "EW", "EFW", "EUW"}


def test_names_are_tried_longest_first():
    names = cat.names_longest_first()
    assert names.index("PF") < names.index("P") and names.index("EFW") < names.index("E" "W")


def test_an_unknown_key_is_refused(tmp_path):
    path = tmp_path / "commands.toml"
    path.write_text('[command.Q]\nmotoin = true\n', encoding="utf-8")
    with pytest.raises(ValueError, match="motoin"):
        cat.catalogue(path)


def test_a_catalogue_that_lacks_a_command_is_refused(tmp_path):
    path = tmp_path / "commands.toml"
    path.write_text('[command.Q]\n', encoding="utf-8")
    with pytest.raises(ValueError, match="differ from the profiles"):
        cat.catalogue(path)
