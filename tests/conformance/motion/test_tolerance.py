"""The processing window and the tolerance of motion checks (conformance/motion/tolerance)."""

from __future__ import annotations

from conformance.motion.tolerance import (
    PLACEMENT_STEPS,
    Window,
    byte_ns,
    processing_window,
    reading_band,
    since,
    tolerance,
)
from conformance.targets import parse_target


def test_byte_time_is_ten_bits() -> None:
    assert byte_ns(115200) == round(10e9 / 115200)
    assert byte_ns(1_000_000_000) == 10


def test_virtual_window_is_the_instant_the_frame_completed() -> None:
    # on the emulator the answer leaves the moment the frame's CR is in: both ends agree
    link = parse_target("emu:GVE84-100").open_link()
    r = link.send("PF")
    w = processing_window(r.sent_at, r.received_at, len(b"!0PF\r"), len(r.raw), link.baud,
                          virtual=True, paced=True)
    assert w.lo == w.hi == r.received_at - len(r.raw) * byte_ns(link.baud)
    assert tolerance(w, exact=True).exact


def test_paced_window_leaves_out_the_bytes_on_the_wire() -> None:
    b = byte_ns(9600)
    w = processing_window(0, 20 * b + 500, 5, 10, 9600, virtual=False, paced=True)
    assert (w.lo, w.hi) == (5 * b, 10 * b + 500)
    t = tolerance(w, exact=False)
    assert t.steps == PLACEMENT_STEPS and t.seconds == (5 * b + 500) / 1e9


def test_unpaced_or_too_fast_window_is_the_whole_round_trip() -> None:
    assert processing_window(100, 400, 5, 10, 9600, virtual=False, paced=False) == Window(100, 400)
    # a round trip shorter than the bytes' time: the line was not paced after all
    assert processing_window(100, 400, 5, 10, 9600, virtual=False, paced=True) == Window(100, 400)


def test_elapsed_time_adds_both_uncertainties() -> None:
    assert since(Window(1000, 1100), Window(100, 150)) == Window(850, 1000)


def test_reading_band() -> None:
    # 10 000 steps/s, instants up to 0.5 ms apart: 5 steps, plus one per real target
    assert reading_band(Window(0, 500_000), Window(0, 0), 10_000) == 5 + 2 * PLACEMENT_STEPS
    assert reading_band(Window(7, 7), Window(7, 7), 10_000, placement=0) == 0
