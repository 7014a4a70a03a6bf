"""The index read in every form a reader of the manuals could write it."""

from conformance.protocol.index import Form, ambiguous, evident, measure, readable, value


def test_a_text_is_read_in_either_form_and_only_a_number_no_form_reads_is_unreadable():
    assert value("59", Form.DECIMAL) == 59 and value("3B", Form.HEX) == 59
    assert value("3b", Form.HEX) == 59 and value("007", Form.DECIMAL) == 7
    assert value("3B", Form.DECIMAL) is None and value("256", Form.DECIMAL) is None
    assert readable("3B") and readable("255") and readable("0A")
    assert not readable("300") and not readable("") and not readable("-1") \
        and not readable("1G") and not readable("0x1")


def test_the_form_shows_itself_only_where_the_bases_differ():
    assert evident("3B") is Form.HEX and evident("255") is Form.DECIMAL
    assert evident("7") is None and evident("10") is None
    assert ambiguous("10") and not ambiguous("7") and not ambiguous("3B")


class Unit:
    """An index that moves by ``step`` a counted frame, written in ``form``."""

    def __init__(self, start: int, step: int, form: Form) -> None:
        self.index, self.step, self.form, self.reads = start, step, form, 0

    def read(self) -> str:
        self.reads += 1
        return "%02X" % self.index if self.form is Form.HEX else str(self.index)

    def move(self) -> None:
        self.index = (self.index + self.step) % 256


def test_measuring_moves_the_index_until_its_form_shows():
    for start in range(256):
        for step in (1, 2):
            for form in Form:
                unit = Unit(start, step, form)
                assert measure(unit.read, unit.move) is form, (start, step, form)
                assert unit.reads <= 12


def test_an_index_that_never_moves_or_answers_is_taken_as_decimal():
    unit = Unit(16, 0, Form.HEX)
    assert measure(unit.read, unit.move) is Form.DECIMAL
    assert measure(lambda: None, lambda: None) is Form.DECIMAL
