"""How long the link waits for an answer and whether it reads one summed: one rule for
its own frames and for the raw frames the differential sides send."""

import pytest

from conformance.diff.sides import Side
from conformance.targets import parse_target


def link():
    return parse_target("emu:GVE84-100").session.open_link()


def test_an_answer_given_when_the_action_ends_may_take_that_long():
    ln = link()
    immediate = ln.answer_timeout("V1000", 8)
    assert immediate < 1                         # the bytes and a margin
    assert ln.answer_timeout("V1000", 80) > immediate
    slow = ln.guard.answer_seconds("H")
    assert slow > 0 and ln.answer_timeout("H", 8) - immediate == pytest.approx(slow)


def test_the_answer_is_summed_as_the_mode_is_after_the_command():
    ln = link()
    assert ln.summed_after("%+") and not ln.summed_after("V1000")
    ln.checksums = True
    assert ln.summed_after("V1000") and not ln.summed_after("%-") and not ln.summed_after("J")


def test_a_side_reads_the_answer_to_a_mode_change_as_the_link_does():
    side = Side(parse_target("emu:GVE84-100"))
    side.open()
    on = side.exchange(b"!0%+\r", body="%+")
    assert on.code == 0 and on.response.checksum is not None
    assert side.link.send("%-").code == 0
