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
