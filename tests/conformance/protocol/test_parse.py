"""parse(): a body's command and fields, lenient (how a frame is classed) and strict (as
spec 3 writes it)."""

from __future__ import annotations

from conformance.protocol.parse import parse, parse_text, read_int, split_fields


def test_names_are_read_longest_first():
    assert parse("PF").name == "PF" and parse("P").name == "P"
    assert parse("EFW10,1.5").fields == ("10", "1.5")
    assert parse("NQ5").name == "N" and parse("NQ5").params == "Q5"


def test_glued_fields_take_one_character_and_an_optional_comma():
    assert parse("WY,-20000,1000,2000,500").fields == ("Y", "-20000", "1000", "2000", "500")
    assert parse("WY-20000,1000").fields == ("Y", "-20000", "1000")
    assert parse("M4").fields == ("4",) and parse("M").fields == ()
    assert split_fields("%", "+") == ("+",)


def test_lenient_reads_either_case_strict_only_upper():
    assert parse("sw6,00").name == "SW" and parse("sw6,00").key == "SW6"
    assert parse("sw6,00", strict=True).name is None
    assert parse("sw6,00", strict=True).key == ""


def test_a_write_of_st6():
    assert parse("SW+6,00").key == "SW6"
    assert parse("SW+6,00", strict=True).key == "SW"      # `+6` is no decimal of spec 3
    assert parse("SW60,00").key == "SW" and parse("SR6").key == "SR"


def test_no_command():
    assert parse("ZZ").name is None and parse("ZZ").key == "" and parse("").key == ""


def test_the_address_before_the_body():
    p = parse_text("3L1,2,3")
    assert (p.address, p.name, p.fields) == (3, "L", ("1", "2", "3"))
    assert parse_text("9Q").address is None


def test_integers():
    assert read_int(" +6") == 6 and read_int(" +6", strict=True) is None
    assert read_int("0A", base=16) == 10 and read_int("x") is None
