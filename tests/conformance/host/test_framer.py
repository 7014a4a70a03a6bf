"""The host's byte stream cut into frames, every byte with its instant (spec 3)."""

from __future__ import annotations

from conformance.host.framer import Fragment, HostFrame, HostFramer


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
