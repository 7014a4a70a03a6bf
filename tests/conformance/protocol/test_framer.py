"""The host's byte stream cut into frames, every byte with its instant (spec 3)."""

from __future__ import annotations

from itertools import pairwise

import pytest
from hypothesis import given
from hypothesis import strategies as st

from conformance.protocol.framer import KEEP, Fragment, HostFrame, HostFramer


def feed(framer: HostFramer, *chunks: tuple[bytes, int]) -> list:
    return [item for data, t in chunks for _, item in framer.feed(data, t)]


def test_frames_split_over_chunks_keep_each_bytes_instant():
    f = HostFramer()
    out = feed(f, (b"!0V1", 0), (b"00\r!0A", 20), (b"5\r", 45))
    assert [(x.raw, x.times, x.end) for x in out] == [
        (b"!0V100", [0, 0, 0, 0, 20, 20], 20), (b"!0A5", [20, 20, 20, 45], 45)]
    assert out[0].slowest_gap == 20 and out[1].pauses[-1] == (45, 45)


def test_fragments():
    f = HostFramer()
    out = feed(f, (b"xx!0V1!0A5\r\n", 7))
    assert [(type(x).__name__, getattr(x, "kind", ""), x.raw if isinstance(x, HostFrame)
             else x.data) for x in out] == [
        ("Fragment", "stray", b"xx"), ("Fragment", "cut", b"!0V1"),
        ("HostFrame", "", b"!0A5"), ("Fragment", "lf", b"\n")]


def test_offsets_say_where_each_item_ends():
    f = HostFramer()
    events = f.feed(b"ab!0V1!0A5\r", 0)
    assert [end for end, _ in events] == [2, 6, 11]     # stray, cut (before `!`), frame


def test_the_end_of_the_run_closes_what_is_open():
    f = HostFramer()
    feed(f, (b"!0V10", 0))
    (frag,) = f.finish(5)
    assert isinstance(frag, Fragment) and frag.kind == "cut" and frag.data == b"!0V10"



def both_ways(stream: bytes, bounds: list[int]) -> tuple[list, list]:
    """The items (with the stream offset each ends at) when ``stream`` comes in the
    chunks between ``bounds``, and when it comes a byte at a time (each byte stamped
    with its chunk's instant), the end of the run included."""
    whole, single = HostFramer(), HostFramer()
    by_chunk, by_byte = [], []
    for n, (a, b) in enumerate(pairwise(bounds)):
        by_chunk += [(a + end, item) for end, item in whole.feed(stream[a:b], n)]
        for i in range(a, b):
            by_byte += [(i + end, item) for end, item in single.feed(stream[i:i + 1], n)]
    return by_chunk + whole.finish(99), by_byte + single.finish(99)


@given(st.lists(st.tuples(st.sampled_from([b"!", b"\r", b"\n", b"0", b"V1", b"x"]),
                          st.booleans()), max_size=40))
def test_any_chunking_cuts_the_same_as_one_byte_at_a_time(pieces):
    """Whole frames in a chunk take a quicker path; the cut is the one a byte at a time
    gives, items and offsets alike."""
    stream = b"".join(p for p, _ in pieces)
    ends = [sum(len(p) for p, _ in pieces[: k + 1]) for k, (_, cut) in enumerate(pieces)
            if cut]
    by_chunk, by_byte = both_ways(stream, [0, *ends, len(stream)])
    assert by_chunk == by_byte


@pytest.mark.parametrize("length", [KEEP - 1, KEEP, KEEP + 1])
def test_a_frame_about_as_long_as_is_kept_cuts_the_same_in_one_chunk(length):
    stream = b"!0A5\r" + b"!0V" + b"1" * (length - 3) + b"\r\n!0A5\r"
    by_chunk, by_byte = both_ways(stream, [0, 5, len(stream)])
    assert by_chunk == by_byte
    assert [len(item.raw) for _, item in by_chunk if isinstance(item, HostFrame)] == [
        4, min(length, KEEP), 4]
