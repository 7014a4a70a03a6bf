"""The booking reads frames and books the units' views when asked, in the relay's order:
the same readings and the same executed motion as reading and booking each at once."""

from __future__ import annotations

from conformance.host.booking import Booking
from conformance.host.frame_rules import byte_sum, parse_frame
from conformance.host.recording import Exchange
from conformance.host.unitview import line_views
from conformance.protocol.framer import HostFrame
from tests.conformance.host.records import MS, PROFILE, UNITS


def summed(body: bytes) -> bytes:
    return body + b",%02X" % byte_sum(body + b",")


#: a job as the relay sees it: frames with the unit's answers (None: a packet member),
#: and a power cycle of the unit between them
JOB: list[tuple[bytes, bytes | None] | str] = [
    (b"!0%+", b"0,5C\r"),                     # checksum mode on (spec 6)
    (summed(b"!0L100,0,0"), b"0,30\r"),
    (summed(b"!0*S"), None),
    (summed(b"!0C1,0,0"), None),
    (summed(b"!0*E1"), b"0,1,5D\r"),
    "power-on",                               # checksum mode off again
    (b"!0L5,0,0", b"0\r"),
]


def exchanges() -> list[Exchange | str]:
    out: list[Exchange | str] = []
    for n, item in enumerate(JOB):
        if isinstance(item, str):
            out.append(item)
            continue
        raw, answer = item
        ex = Exchange(n, HostFrame(raw, [n * MS] * len(raw), n * MS), to_unit=raw + b"\r")
        ex.answer, ex.answered_at = ([answer], n * MS) if answer else ([], None)
        out.append(ex)
    return out


def lazily() -> tuple[Booking, list[Exchange]]:
    booking, done = Booking(line_views([(PROFILE, 0)])), []
    for item in exchanges():
        if isinstance(item, str):
            booking.power_on(0, 0)
        else:
            booking.frame(item)
            booking.answered(item)
            done.append(item)
    return booking, done


def test_nothing_is_read_until_asked():
    _, done = lazily()
    assert all(ex.reading is None for ex in done)
    assert done[1].parsed.command == "L"          # asking one reads up to where it stands
    assert all(ex.reading is not None for ex in done)


def test_a_frame_is_read_in_the_checksum_mode_of_its_time():
    booking, done = lazily()
    booking.settle()
    in_mode, after_restart = done[1].parsed, done[-1].parsed
    assert "6.checksum.sum" in in_mode.judged and not in_mode.problems
    assert "6.checksum.sum" not in after_restart.judged and not after_restart.problems


def test_the_accepted_vectors_as_each_frame_came():
    booking, done = lazily()
    assert booking.vectors() == 3
    assert [ex.vectors_before for ex in done] == [0, 0, 1, 1, 1, 2]


def test_the_same_books_as_reading_and_booking_at_once():
    eager = line_views([(PROFILE, 0)])
    view, readings = eager[0], []
    for item in exchanges():
        if isinstance(item, str):
            view.power_on(0)
            continue
        item.reading = parse_frame(item.frame.raw, UNITS, view.checksums)
        readings.append(item.reading)
        view.apply(item, UNITS)
    booking, done = lazily()
    booking.settle()
    assert [ex.parsed for ex in done] == readings
    assert booking.views[0].executed == view.executed
    assert (booking.views[0].checksums, booking.views[0].packet) == (view.checksums, view.packet)
