"""The index compared from each side's first reading of it: a unit whose first `@`
counts itself agrees; one off later by exactly the queries since is the counting reading;
one off by anything else miscounts."""

from conformance.diff.index import IndexBase


def test_the_first_reading_sets_the_base():
    base = IndexBase()
    base.note("@", set(), ["1"], ["0"])
    assert base.offset == 1 and base.queries == 0


def test_a_query_sent_so_that_no_unit_counts_it_sets_nothing():
    base = IndexBase()
    base.note("@", {"bad-checksum"}, ["7"], ["0"])
    base.note(">", set(), ["7"], ["0"])
    assert base.offset is None


def test_an_index_off_by_the_queries_since_is_the_counting_reading():
    base = IndexBase()
    base.note("@", set(), ["1"], ["0"])       # counts itself before answering
    base.note(">", set(), [], [])
    base.note("@", set(), ["4"], ["1"])       # one frame counted by both, 2 queries
    assert base.counts_queries(["4"], ["1"])
    assert not base.counts_queries(["3"], ["1"])    # off by one: not the queries
    assert not base.counts_queries(["2"], ["1"])    # the same index: no reading at all


def test_it_wraps_modulo_256():
    base = IndexBase()
    base.note("@", set(), ["255"], ["0"])     # one behind the reference
    base.note("@", set(), ["1"], ["1"])       # and one query since: level again
    assert base.counts_queries(["1"], ["1"])
    assert not base.counts_queries(["0"], ["1"])


def test_an_index_written_in_hex_is_told_from_a_miscount():
    base = IndexBase()
    base.note("@", set(), ["00"], ["0"])
    assert base.in_hex(["0A"], ["10"]) and base.in_hex(["10"], ["16"])
    # a miscount stays one, in either form; the same bytes are no difference
    assert not base.in_hex(["0B"], ["10"]) and not base.in_hex(["10"], ["10"])
    assert not base.in_hex(["11"], ["10"])


def test_the_hex_base_is_the_first_index_read_as_hex():
    base = IndexBase()
    base.note("@", set(), ["1A"], ["3"])          # 26 read as hex: 23 ahead
    assert base.offset is None and base.hex_offset == 23
    assert base.in_hex(["2A"], ["19"]) and not base.in_hex(["2A"], ["20"])


def test_a_hex_index_read_before_the_sequence_is_based_in_both_forms():
    # a co-simulator's index, read before the sequence, written in two hex digits
    base = IndexBase.read(["C0"], 2)
    assert base.offset is None and base.hex_offset == 0xC0 - 2
    assert base.in_hex(["C3"], ["5"])
    base.note("@", set(), ["C3"], ["5"])
    assert base.queries == 1               # based already: the query counts from there


def test_an_index_off_by_the_refused_frames_since_leaves_them_out():
    base = IndexBase.read(["10"], 0)      # decimal 10, or hex 16
    for _ in range(2):
        base.refused_frame("T", set())
    base.refused_frame("V", {"bad-checksum"})   # no unit counts it: not one more
    base.refused_frame("@", set())              # a query: not one more
    assert base.refused == 2
    assert base.skips_refused(["13"], ["5"])    # 10 + 5 - 2
    assert base.skips_refused(["1A"], ["12"])   # hex 0x1A = 26 = 16 + 12 - 2
    assert not base.skips_refused(["15"], ["5"])
