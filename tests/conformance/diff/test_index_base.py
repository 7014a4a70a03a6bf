"""The index compared from each side's first reading of it: a unit whose first `@`
counts itself agrees; one off later by exactly the queries since is the counting reading;
one off by anything else miscounts."""

from conformance.diff.index_base import IndexBase


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


def test_an_index_short_by_the_refused_frames_since_is_the_reading_that_counts_what_it_took():
    base = IndexBase()
    base.refused_frame("T", set())            # before the base: not counted
    base.note("@", set(), ["5"], ["5"])
    base.refused_frame("T", set())
    base.refused_frame("Z", set())
    base.refused_frame("V", {"bad-checksum"})  # no unit counts it: not a refusal
    assert base.refused == 2
    assert base.skips_refused(["6"], ["8"])        # two refused frames not counted
    assert not base.skips_refused(["7"], ["8"])    # one short: a miscount
    assert not base.skips_refused(["8"], ["8"])    # the same: no reading at all
    base.note("@", set(), ["6"], ["8"])            # a query since, counted by neither
    assert base.skips_refused(["6"], ["8"])
    assert base.skips_refused(["7"], ["8"])        # and one that counts the query
