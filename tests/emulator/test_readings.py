"""Every reading of emulator/readings.py really reads the manual otherwise: the frame of
its point answered differently from the clean emulator, as its description says; several
readings at once; and every name the emulator asks ``active()`` about is registered."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from emulator.protocol.unit import Unit
from emulator.readings import CORE_READINGS, READINGS, Readings, UnknownReading, parse_readings
from gve_fixtures.rules import load_rules

EMULATOR = Path(__file__).resolve().parents[1].parent / "emulator"

#: reading -> (frames, (port, level) the rig sets, or the seconds until the next one when
#: not a second; the clean emulator's answers, the reading's)
Step = bytes | tuple[int, int] | float
POINTS: dict[str, tuple[list[Step], bytes, bytes]] = {
    "plus-sign": ([b"!0V+100\r"], b"4\r", b"0\r"),
    # one byte: 255 taken, 256 beyond it
    "accel-byte-range": ([b"!0A255\r", b"!0A256\r"], b"0\r0\r", b"0\r5\r"),
    "long-version": ([b"!0?\r"], b"0,IP84 v3 27.1.2010\r",
                     b"0,IP84 v3 27.1.2010 (c) Gravos (P.Borovsky)\r"),
    "go-nothing-queued": ([b"!0H\r", b"!0G\r"], b"8\r0\r", b"8\rE\r"),
    # H, G: the flags cleared either way, then 0 or 6 (with INTA clear: no 8)
    "go-clears-then-nothing": ([b"!0H\r", b"!0G\r", b"!0SR6\r"], b"8\r0\r0,00\r",
                               b"8\r6\r0,00\r"),
    "missing-letter-range": ([b"!0NA0\r"], b"3\r", b"5\r"),
    "lone-bang-answered": ([b"!"], b"", b"2\r"),
    "hex-upper-only": ([b"!0SW2,ab\r"], b"0\r", b"4\r"),
    # three hex digits: a value in range (0) and one beyond FF (5), or syntax errors both
    "hex-two-digits": ([b"!0SW2,001\r", b"!0SW2,100\r"], b"0\r5\r", b"4\r4\r"),
    "queries-counted": ([b"!0@\r", b"!0@\r"], b"0,0\r0,0\r", b"0,1\r0,2\r"),
    # T99 refused (5): counted, or not
    "refused-uncounted": ([b"!0T99\r", b"!0@\r"], b"5\r0,1\r", b"5\r0,0\r"),
    "restore-nothing-kept-refused": ([b"!0R\r"], b"0\r", b"4\r"),
    # STOP written as 1: nothing, or a stop request accepted (INTA, the answer's 8 too)
    "sw6-stop-request": ([b"!0SW6,01\r", b"!0SR6\r"], b"0\r0,00\r", b"8\r8,80\r"),
    # the second K finds the first one's save held
    "second-keep-refused": ([b"!0K\r", b"!0K\r"], b"0\r0\r", b"0\r4\r"),
    # a long vector still running a second later
    "eeprom-write-while-moving": ([b"!0L100000,0,0\r", b"!0EW10,AB\r", b"!0ER10\r"],
                                  b"0\r7\r0,FF\r", b"0\r0\r0,AB\r"),
    # H is a member (unanswered, failing the packet with 4), so *E1 finds one member
    "packet-closed-only-by-end": ([b"!0*S\r", b"!0H\r", b"!0*E1\r"],
                                  b"8\rC,0\r", b"4,1\r"),
    # an empty packet moves the index by its *S and *E, or not at all
    "packet-frames-uncounted": ([b"!0*S\r", b"!0*E0\r", b"!0@\r"],
                                b"0,0\r0,2\r", b"0,0\r0,0\r"),
    # @ answered inside the packet leaves it open: *E0 ends an empty packet
    "packet-open-through-queries": ([b"!0*S\r", b"!0@\r", b"!0*E0\r"],
                                    b"0,1\r4,0\r", b"0,1\r0,0\r"),
    # *E2 for one member fails the packet, but its C ran as it arrived
    "packet-committed-on-arrival": ([b"!0*S\r", b"!0C10,0,0\r", b"!0*E2\r", b"!0PF\r"],
                                    b"2,1\r0,0,0,0\r", b"2,1\r0,10,0,0\r"),
    # a 106-byte frame is run (V with leading zeros); one of 5003 is still too long
    "longer-frames": ([b"!0V" + b"0" * 100 + b"1000\r", b"!0V" + b"1" * 5000 + b"\r"],
                      b"4\r4\r", b"0\r4\r"),
    # INTR0 enabled, grounded (active at 0): D clears INTA, which the input still held
    # sets again at once (8) unless only its edge interrupts (0)
    "edge-triggered-inputs": ([b"!0SW0,01\r", (1, 0xFE), b"!0D\r", b"!0SR4\r"],
                              b"0\r8\r8,01\r", b"0\r0\r0,00\r"),
    # IN0 and IN1 enabled; IN0 grounded stops the unit, then IN1 grounded too: its cause
    # bit is added (03), or only the first interrupt's stays (01)
    "cause-first-only": ([b"!0SW0,03\r", (1, 0xFE), (1, 0xFC), b"!0SR4\r"],
                         b"0\r8,03\r", b"0\r8,01\r"),
    # half a second without a byte inside a frame: dropped (2), or the frame runs whole
    "slow-watchdog": ([b"!0V10", 0.5, b"00\r"], b"2\r", b"0\r"),
    "index-remembered": ([b"!0?\r", b"!0@\r", b"!0>\r"],
                         b"0,IP84 v3 27.1.2010\r0,1\r!0?\r0,IP84 v3 27.1.2010\r",
                         b"0,IP84 v3 27.1.2010\r0,1\r!0@\r0,1\r"),
    # B10 before a junction, B1000 after: at B10 the first C is just ending at 3000 six
    # seconds on; at B1000 it ran on into the second C half a second earlier
    "next-vectors-B": ([b"!0A1\r", b"!0B10\r", b"!0C3000,0,0\r", b"!0B1000\r",
                        b"!0C3000,0,0\r", b"!0A1\r", b"!0PF\r"],
                       b"0\r" * 6 + b"0,3000,0,0\r", b"0\r" * 6 + b"0,3499,0,0\r"),
    # K after H (nothing running: 8 at once), then a second K
    "restore-nothing-kept-range": ([b"!0R\r"], b"0\r", b"5\r"),
    "keep-c-queue-full": ([b"!0K\r", b"!0C1,0,0\r"], b"0\r4\r", b"0\r1\r"),
    # V is no member: the packet fails with 4, counting every member or the valid ones
    "packet-failed-count-valid": ([b"!0*S\r", b"!0C1,0,0\r", b"!0V100\r", b"!0C1,0,0\r",
                                   b"!0*E3\r"], b"4,3\r", b"4,2\r"),
    # the count differs (2, *E1) and V is no member: 2 and k, or V's own 3 and none
    "packet-failed-count-zero": ([b"!0*S\r", b"!0V10\r", b"!0C-300,0,0\r", b"!0*E1\r"],
                                 b"2,2\r", b"3,0\r"),
    # 0.3 s without a byte inside a frame: dropped (2), or the frame runs whole
    "half-second-watchdog": ([b"!0V10", 0.3, b"00\r"], b"2\r", b"0\r"),
    # 0.7 s without a byte inside a packet: *E1 commits it, or the packet was dropped
    "packet-watchdog": ([b"!0*S\r", 0.1, b"!0C1,0,0\r", 0.7, b"!0*E1\r"],
                        b"0,1\r", b"2,1\r4,0\r"),
    "vector-fewer-components": ([b"!0L5,3\r", b"!0PF\r"], b"4\r0,0,0,0\r",
                                b"0\r0,5,3,0\r"),
    "commands-any-case": ([b"!0v1000\r"], b"3\r", b"0\r"),
    # the GVE84 lacks EFR but has ER; it has no command beginning Y
    "absent-command-syntax": ([b"!0EFR30\r", b"!0Y-\r"], b"3\r3\r", b"4\r3\r"),
    # eleven counted frames: the index 11 in decimal, or two hex digits
    "index-hex": ([b"!0SR6\r"] * 11 + [b"!0@\r"], b"0,00\r" * 11 + b"0,11\r",
                  b"0,00\r" * 11 + b"0,0B\r"),
    "eeprom-erased-zero": ([b"!0ER40\r"], b"0,FF\r", b"0,00\r"),
    # 1 ms after L0,0,0 its T5 dwell still holds RUN: N refused, SR6 shows RUN
    "zero-vector-dwells": ([b"!0L0,0,0\r", 0.001, b"!0N\r", 0.001, b"!0SR6\r"],
                           b"0\r0\r0,00\r", b"0\r7\r0,40\r"),
    # 1 ms after L0,0,0 an H at rest leaves its T5 dwell running: D refused, RUN with INTA
    "dwell-outlives-halt": ([b"!0L0,0,0\r", 0.001, b"!0H\r", 0.001, b"!0D\r", 0.001,
                             b"!0SR6\r"],
                            b"0\r8\r0\r0,00\r", b"0\r8\rF\r8,D0\r"),
    # 0.1 s into L300,400 under VK at V2000 and the reset's A: Y (n = 400 of |d| = 500)
    # ramps at A, or at A·400/500 along the path
    "accel-along-path": ([b"!0VK\r", 0.001, b"!0V2000\r", 0.001, b"!0L300,400,0\r", 0.1,
                          b"!0PF\r"], b"0\r0\r0\r0,71,95,0\r", b"0\r0\r0\r0,59,79,0\r"),
    # a halted L holds RUN: R refused, where the clean unit restores an empty save
    # a C sent while an L runs: queued behind it, or 1 until the L has ended (then 0)
    "cont-waits-for-line": ([b"!0L1000,0,0\r", 0.001, b"!0C10,0,0\r", 1.5, b"!0C10,0,0\r"],
                            b"0\r0\r0\r", b"0\r1\r0\r"),
    "restore-refused-while-run": ([b"!0L1000,0,0\r", 0.01, b"!0H\r", b"!0R\r"],
                                  b"0\r8\r0\r", b"0\r8\rF\r"),
    # C700 then C-700 at A5, B500: 0.7 s on the reversal is passed at B500 (back at 677)
    # or braked to rest there (still at 694)
    "reversal-brakes-to-rest": ([b"!0A5\r", 0.001, b"!0B500\r", 0.001, b"!0V2000\r", 0.001,
                                 b"!0C700,0,0\r", 0.001, b"!0C-700,0,0\r", 0.7, b"!0PF\r"],
                                b"0\r" * 5 + b"0,677,0,0\r", b"0\r" * 5 + b"0,694,0,0\r"),
    # 0.5 s into L30000 at V20000 and the reset's A20 (20 000 pulses/s², 2500 steps in, at
    # 10 000 pulses/s): a tick earlier the counter read 10 steps less
    "counters-a-tick-late": ([b"!0V20000\r", b"!0L30000,0,0\r", 0.5, b"!0PF\r"],
                             b"0\r0\r0,2499,0,0\r", b"0\r0\r0,2489,0,0\r"),
    # 50 ms into L100 at the reset's A20 the X counter shows one step less
    "steps-a-period-late": ([b"!0L100,0,0\r", 0.05, b"!0PF\r"], b"0\r0,24,0,0\r",
                            b"0\r0,23,0,0\r"),
}
#: the MPG's limits, steps per mm, acceleration, speed and delay, each in its range
_MPG_SETTINGS: list[Step] = [
    *(b"!0EFW%02X,%d\r" % (0x10 + 4 * i, 0 if i < 4 else 1000) for i in range(8)),
    *(b"!0EFW%02X,100\r" % (0x30 + 4 * i) for i in range(4)),
    b"!0EFW40,100\r", b"!0EFW44,10\r", b"!0EUW48,100\r"]
#: readings of what only the GVE114 has, on a GVE114-500: EEPROM 06 enables the MPG; its
#: parameters are erased (FF), so under the reading it does not hold RUN after J
POINTS_114: dict[str, tuple[list[Step], bytes, bytes]] = {
    # Y& while an L runs: taken, or 7 while the axes move
    "mpg-refused-while-moving": ([b"!0L1000,0,0,0\r", 0.001, b"!0Y&\r"], b"0\r0,Y&\r",
                                 b"0\r7\r"),
    "mpg-needs-parameters": ([b"!0EW06,01\r", b"!0J\r", 2.5, b"!0SR6\r", b"!0Y+\r"],
                             b"0\r0\r0,40\r0,Y+\r", b"0\r0\r0,00\r5\r"),
    # every MPG setting of 12.4-12.7 in range, the spindle speed (4C) still erased
    "mpg-needs-every-parameter": ([*_MPG_SETTINGS, b"!0EW06,01\r", b"!0J\r", 2.5,
                                   b"!0SR6\r", b"!0Y+\r"],
                                  b"0\r" * 17 + b"0,40\r0,Y+\r",
                                  b"0\r" * 17 + b"0,00\r5\r"),
    # the MPG enabled, then J: the reset's & holds RUN at once, or only once Y& is sent
    "mpg-on-when-sent": ([b"!0EW06,01\r", b"!0J\r", 2.5, b"!0SR6\r", b"!0Y&\r", b"!0SR6\r"],
                         b"0\r0\r0,40\r0,Y&\r0,40\r", b"0\r0\r0,00\r0,Y&\r0,40\r"),
    "set-axis-xyz-only": ([b"!0NA5\r", b"!0NX5\r"], b"0\r0\r", b"4\r0\r"),
}

#: readings of what only the GVE54 has (its motor mode M)
POINTS_54: dict[str, tuple[list[Step], bytes, bytes]] = {
    # a halted L holds RUN: M refused (7 with INTA), where the clean unit takes it
    "motor-mode-refused-while-run": ([b"!0L1000,0,0\r", 0.01, b"!0H\r", b"!0MF\r"],
                                     b"0\r8\r8\r", b"0\r8\rF\r"),
}


#: readings of the line rate: a frame (on the GVE114 EEPROM 0D written, a byte the manual
#: does not list), the rate switch at its first position (sw1 OFF sw2 OFF), power-on: the
#: rate read (profile, frame, clean, reading)
RATE_POINTS: dict[str, tuple[str, bytes, int, int]] = {
    "baud-unlisted-high": ("GVE114-500", b"!0EW0D,00\r", 19200, 921600),
    "rate-jumpers-reversed": ("GVE54", b"!0?\r", 9600, 115200),
}


def rate_after_power_on(readings: tuple[str, ...], profile: str, frame: bytes) -> int | None:
    unit = Unit(profile, readings=readings)
    unit.receive(frame, 10**9, 1000)
    unit.set_rate_switch(0)
    unit.power_on(2 * 10**9)
    return unit.device.rate


def answers(readings: tuple[str, ...], frames: list[Step], profile: str = "GVE84-100"
            ) -> bytes:
    """What a unit of ``profile`` taking ``readings`` answers ``frames``, a second apart
    unless a number says otherwise."""
    unit = Unit(profile, readings=readings)
    out: list[bytes] = []
    unit.emit = lambda data, t: out.append(data)
    t = 10**9
    for i, frame in enumerate(frames):
        if isinstance(frame, float):
            continue
        if isinstance(frame, tuple):
            unit.set_input(*frame, t)
        else:
            unit.receive(frame, t, 1000)
        after = frames[i + 1] if i + 1 < len(frames) else None
        t += int(after * 10**9) if isinstance(after, float) else 10**9
        unit.advance(t)
    return b"".join(out)


def test_every_reading_has_its_point_here():
    assert set(POINTS) | set(POINTS_114) | set(POINTS_54) | set(RATE_POINTS) == set(READINGS)


@pytest.mark.parametrize("name", sorted(RATE_POINTS))
def test_a_reading_of_the_rate_picks_another_rate(name):
    profile, frame, clean, read = RATE_POINTS[name]
    assert rate_after_power_on((), profile, frame) == clean
    assert rate_after_power_on((name,), profile, frame) == read


@pytest.mark.parametrize("name", sorted(POINTS))
def test_a_reading_answers_its_point_otherwise(name):
    frames, clean, read = POINTS[name]
    assert answers((), frames) == clean
    assert answers((name,), frames) == read


@pytest.mark.parametrize("name", sorted(POINTS_114))
def test_a_reading_of_the_gve114_answers_its_point_otherwise(name):
    frames, clean, read = POINTS_114[name]
    assert answers((), frames, "GVE114-500") == clean
    assert answers((name,), frames, "GVE114-500") == read


@pytest.mark.parametrize("name", sorted(POINTS_54))
def test_a_reading_of_the_gve54_answers_its_point_otherwise(name):
    frames, clean, read = POINTS_54[name]
    assert answers((), frames, "GVE54") == clean
    assert answers((name,), frames, "GVE54") == read


def test_readings_combine():
    assert answers(("plus-sign", "queries-counted"), [b"!0V+100\r", b"!0@\r"]) == b"0\r0,2\r"


def test_a_frame_the_index_never_counted_is_not_taken_back_when_refused():
    # refused frames uncounted, queries counted: a frame whose checksum fails (4) and one
    # the watchdog drops (2) never counted; the refused T99 (5) is taken back; `>` counts
    both = ("refused-uncounted", "queries-counted")
    assert answers(both, [b"!0%+\r", b"!0V100,00\r", b"!0@,BD\r"]) == \
        b"0,5C\r4,60\r0,2,BA\r"
    assert answers(both, [b"!0V10", 0.5, b"!0@\r"]) == b"2\r0,1\r"
    assert answers(both, [b"!0T99\r", b"!0>\r", b"!0@\r"]) == \
        b"5\r!0T99\r5\r0,2\r"


def test_every_reading_reads_a_rule_the_manuals_leave_open():
    rules = load_rules()
    for name, spec in READINGS.items():
        assert spec.rules and all(r in rules for r in spec.rules), name
        # a reading of an [M] point would be a mutant; the spec's two-way points are [D]
        # in the text of an [M] rule's table (codes 3/5, 6)
        assert any(rules[r].tag.startswith("D") for r in spec.rules) or name in (
            "go-nothing-queued", "missing-letter-range"), name


def test_an_unknown_reading_is_refused():
    with pytest.raises(UnknownReading, match="unknown reading"):
        parse_readings("plus-sign,nosuch")
    with pytest.raises(UnknownReading):
        Readings(frozenset({"plus-sign"})).active("nosuch")


def test_every_reading_the_emulator_asks_about_is_registered():
    asked = {a or b for path in EMULATOR.rglob("*.py")
             for a, b in ASKED.findall(path.read_text())}
    # the rest are planted in the stepper core, as deviations
    assert asked | set(CORE_READINGS) == set(READINGS)
    assert not asked & set(CORE_READINGS)


ASKED = re.compile(r'readings\.active\("([^"]+)"\)|reads\("([^"]+)"\)')
