"""The one reader of numbers and JSON from a target: ASCII digits only, at most DIGITS of
them, JSON within a length and a depth; anything else is not a value (None, or
Unreadable saying why), never another exception."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from conformance.protocol import bounded
from conformance.protocol.bounded import DIGITS, Unreadable, decimal, hexadecimal, json_value
from conformance.protocol.parse import read_int
from conformance.protocol.wire import UnitDataError, parse_response


@given(st.text(max_size=30))
def test_a_decimal_is_ascii_digits_only(text):
    value = decimal(text, signed=True)
    digits = text.removeprefix("-")
    ascii_digits = digits.isascii() and digits.isdigit() and 0 < len(digits) <= DIGITS
    assert (value is not None) == ascii_digits
    if value is not None:
        assert value == int(text)


@pytest.mark.parametrize("text", ["²", "٣", "①", "1_000", " 7", "+5", "", "-", "0x10",
                                  "9" * (DIGITS + 1), "9" * 5000])
def test_what_int_would_take_or_choke_on_is_no_number(text):
    assert decimal(text, signed=True) is None and hexadecimal(text) is None
    assert read_int(text, strict=True) is None


def test_the_longest_numbers_are_read():
    assert decimal("9" * DIGITS) == 10**DIGITS - 1
    assert decimal("-12", signed=True) == -12 and decimal("-12") is None
    assert hexadecimal("fF") == 255


@pytest.mark.parametrize("text", ["[" * 100_000 + "]" * 100_000, '{"a":' * 100_000,
                                  "[" * (bounded.JSON_DEPTH + 1) + "]" * (bounded.JSON_DEPTH + 1),
                                  "NaN", '{"x": Infinity}', "1" * 5000, "{not json",
                                  " " * (bounded.JSON_CHARS + 1)])
def test_json_beyond_its_bounds_is_unreadable(text):
    with pytest.raises(Unreadable):
        json_value(text)


def test_brackets_inside_strings_do_not_nest():
    text = '{"a": "' + "[" * 1000 + '\\"]", "b": [[1]]}'
    assert bounded.depth(text) == 3
    assert json_value(text)["b"] == [[1]]


@given(st.text(alphabet='[]{}":,0123456789.eE+-nultrsfa\\ ', max_size=200))
def test_any_text_is_json_or_unreadable_saying_why(text):
    try:
        json_value(text)
    except Unreadable as err:
        assert str(err).startswith(("not JSON", "JSON nested")), err


def test_an_answer_with_a_number_beyond_any_field_is_the_unit_s_fault():
    r = parse_response(b"0," + b"9" * 5000 + b"\r", summed=False)
    with pytest.raises(UnitDataError, match=r'has "9{80}\.\.\." where a decimal'):
        r.dec()
    r = parse_response(b"0,\xb2\x1b\r", summed=False)
    with pytest.raises(UnitDataError, match=r'has "\\xB2\\x1B" where a decimal'):
        r.dec()
